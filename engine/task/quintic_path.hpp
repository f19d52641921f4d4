#pragma once
// A path through vertices with one quintic per segment (zero velocity and acceleration at both ends,
// seed 000 Eq. 40): p(t) = p0 + (p1 - p0)(10 s^3 - 15 s^4 + 6 s^5), s = (t - t0) / T.
// The same type serves positions (Dim = 2 or 3, m) and the vertex orientations of vertex_alpha (Dim = 1, rad).
#include <Eigen/Core>
#include <stdexcept>
#include <vector>

namespace ks {

template <int Dim>
struct PathSample {
  Eigen::Matrix<double, Dim, 1> p, v, a;  ///< value, first and second time derivative
};

template <int Dim>
class QuinticPath {
 public:
  using Point = Eigen::Matrix<double, Dim, 1>;

  /// vertices: n >= 2 points; durations: n - 1 segment durations [s], each > 0.
  QuinticPath(std::vector<Point> vertices, std::vector<double> durations)
      : vertices_(std::move(vertices)), durations_(std::move(durations)) {
    if (vertices_.size() < 2 || durations_.size() + 1 != vertices_.size())
      throw std::invalid_argument("QuinticPath: need n >= 2 vertices and n - 1 segment durations");
    double t = 0.0;
    for (double d : durations_) {
      if (!(d > 0.0)) throw std::invalid_argument("QuinticPath: segment durations must be > 0");
      t += d;
      ends_.push_back(t);
      inverse_.push_back(1.0 / d);
    }
  }

  double duration() const { return ends_.back(); }
  std::size_t segments() const { return durations_.size(); }
  const std::vector<Point>& vertices() const { return vertices_; }
  const std::vector<double>& durations() const { return durations_; }

  /// Segment of time t as the seed chooses it: the first segment whose end time satisfies t <= end
  /// (t <= 0.5 -> A, 0.5 < t <= 1 -> B, ...); times past the end stay on the last segment.
  std::size_t segment_at(double t) const {
    std::size_t i = 0;
    while (i + 1 < ends_.size() && t > ends_[i]) ++i;
    return i;
  }

  /// Value, velocity and acceleration at time t [s].
  PathSample<Dim> sample(double t) const { return sample_on(segment_at(t), t); }

  PathSample<Dim> sample_on(std::size_t i, double t) const {
    const double iT = inverse_[i];  // multiply by 1/T: no division in the simulation's hot loop
    const double s = (t - (ends_[i] - durations_[i])) * iT;
    const double s2 = s * s, s3 = s2 * s;
    const double h = s3 * (10.0 - 15.0 * s + 6.0 * s2);
    const double hd = 30.0 * s2 * (1.0 - 2.0 * s + s2) * iT;
    const double hdd = 60.0 * s * (1.0 - 3.0 * s + 2.0 * s2) * (iT * iT);
    const Point d = vertices_[i + 1] - vertices_[i];
    return {vertices_[i] + h * d, hd * d, hdd * d};
  }

 private:
  std::vector<Point> vertices_;
  std::vector<double> durations_;
  std::vector<double> ends_;
  std::vector<double> inverse_;  // 1 / durations
};

using Path2 = QuinticPath<2>;
using Path3 = QuinticPath<3>;
using Profile1 = QuinticPath<1>;

/// A planar path as a path in space: the same vertices with z = 0 [m], the same durations [s].
inline Path3 lift_to_3d(const Path2& path) {
  std::vector<Path3::Point> v;
  v.reserve(path.vertices().size());
  for (const auto& p : path.vertices()) v.emplace_back(p.x(), p.y(), 0.0);
  return Path3(std::move(v), path.durations());
}

/// The seed's square: (1.5, 1.5) -> (1.5, 2) -> (2, 2) -> (2, 1.5) -> (1.5, 1.5), 0.5 s per side.
inline Path2 seed_square() {
  return Path2({Eigen::Vector2d(1.5, 1.5), Eigen::Vector2d(1.5, 2.0), Eigen::Vector2d(2.0, 2.0),
                Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(1.5, 1.5)},
               {0.5, 0.5, 0.5, 0.5});
}

}  // namespace ks
