#pragma once
// A path through timed vertices, in one of two shapes (PathShape):
//  - quintic: one rest-to-rest quintic per segment (zero velocity and acceleration at both ends, seed 000
//    Eq. 40): p(t) = p0 + (p1 - p0)(10 s^3 - 15 s^4 + 6 s^5), s = (t - t0) / T;
//  - a spline: the C2 cubic spline of each coordinate against time through the vertices (seed 002
//    Eq. 2.20, its timed waypoints), with natural ends (zero acceleration) or clamped ends (zero
//    velocity: at rest at both ends). Its coefficients are computed once, in the constructor.
// The same type serves positions (Dim = 2 or 3, m) and the vertex orientations of vertex_alpha (Dim = 1,
// rad; always quintic).
#include <Eigen/Core>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace ks {

/// How a path joins its vertices: a rest-to-rest quintic per segment, or a cubic spline through them.
enum class PathShape { quintic, natural_spline, clamped_spline };

/// "quintic", "natural", "clamped" (the [task] spline key's words for the two splines).
inline std::string_view to_string(PathShape s) {
  return s == PathShape::quintic ? "quintic" : s == PathShape::natural_spline ? "natural" : "clamped";
}

template <int Dim>
struct PathSample {
  Eigen::Matrix<double, Dim, 1> p, v, a;  ///< value, first and second time derivative
};

template <int Dim>
class TaskPath {
 public:
  using Point = Eigen::Matrix<double, Dim, 1>;

  /// vertices: n >= 2 points; durations: n - 1 segment durations [s], each > 0 (the vertices' times are
  /// their running sums from 0); shape: how the segments join them.
  TaskPath(std::vector<Point> vertices, std::vector<double> durations, PathShape shape = PathShape::quintic)
      : vertices_(std::move(vertices)), durations_(std::move(durations)), shape_(shape) {
    if (vertices_.size() < 2 || durations_.size() + 1 != vertices_.size())
      throw std::invalid_argument("TaskPath: need n >= 2 vertices and n - 1 segment durations");
    double t = 0.0;
    for (double d : durations_) {
      if (!(d > 0.0)) throw std::invalid_argument("TaskPath: segment durations must be > 0");
      t += d;
      ends_.push_back(t);
      inverse_.push_back(1.0 / d);
    }
    if (shape_ != PathShape::quintic) fit_spline();
  }

  double duration() const { return ends_.back(); }
  std::size_t segments() const { return durations_.size(); }
  const std::vector<Point>& vertices() const { return vertices_; }
  const std::vector<double>& durations() const { return durations_; }
  PathShape shape() const { return shape_; }

  /// Segment of time t as the seed chooses it: the first segment whose end time satisfies t <= end
  /// (t <= 0.5 -> A, 0.5 < t <= 1 -> B, ...); times past the end stay on the last segment.
  std::size_t segment_at(double t) const {
    std::size_t i = 0;
    while (i + 1 < ends_.size() && t > ends_[i]) ++i;
    return i;
  }

  /// Value, velocity and acceleration at time t [s].
  PathSample<Dim> sample(double t) const { return sample_on(segment_at(t), t); }

  /// Value, velocity and acceleration at time t [s] on segment i (t may lie outside it: the segment's
  /// polynomial continued).
  PathSample<Dim> sample_on(std::size_t i, double t) const {
    if (shape_ != PathShape::quintic) {
      const double u = t - (ends_[i] - durations_[i]);  // [s] since the segment's start
      const Point& b = b_[i];
      const Point& c = c_[i];
      const Point& d = d_[i];
      return {vertices_[i] + u * (b + u * (c + u * d)), b + u * (2.0 * c + (3.0 * u) * d), 2.0 * c + (6.0 * u) * d};
    }
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
  PathShape shape_;
  // splines: segment i is vertex_i + b_i u + c_i u^2 + d_i u^3, u = t - (its start) [s]
  std::vector<Point> b_, c_, d_;

  /// The spline's coefficients from the vertices, the durations h_i and the end conditions: the second
  /// derivatives M_k at the n + 1 vertices solve the tridiagonal system (Thomas algorithm; diagonally
  /// dominant, so no pivoting)
  ///   h_{k-1} M_{k-1} + 2 (h_{k-1} + h_k) M_k + h_k M_{k+1} = 6 (s_k - s_{k-1}),  s_k = (x_{k+1} - x_k) / h_k,
  /// with M_0 = M_n = 0 (natural) or, for zero end velocities (clamped), 2 h_0 M_0 + h_0 M_1 = 6 s_0 and
  /// h_{n-1} M_{n-1} + 2 h_{n-1} M_n = -6 s_{n-1}. Then b_i = s_i - h_i (2 M_i + M_{i+1}) / 6, c_i = M_i / 2,
  /// d_i = (M_{i+1} - M_i) / (6 h_i).
  void fit_spline() {
    const std::size_t n = durations_.size();
    const std::vector<double>& h = durations_;
    const bool clamped = shape_ == PathShape::clamped_spline;
    std::vector<Point> s(n), rhs(n + 1), M(n + 1);
    for (std::size_t k = 0; k < n; ++k) s[k] = (vertices_[k + 1] - vertices_[k]) / h[k];
    std::vector<double> lower(n + 1, 0.0), diag(n + 1, 1.0), upper(n + 1, 0.0);
    rhs[0] = clamped ? Point(6.0 * s[0]) : Point(Point::Zero());
    if (clamped) diag[0] = 2.0 * h[0], upper[0] = h[0];
    for (std::size_t k = 1; k < n; ++k) {
      lower[k] = h[k - 1], diag[k] = 2.0 * (h[k - 1] + h[k]), upper[k] = h[k];
      rhs[k] = 6.0 * (s[k] - s[k - 1]);
    }
    rhs[n] = clamped ? Point(-6.0 * s[n - 1]) : Point(Point::Zero());
    if (clamped) lower[n] = h[n - 1], diag[n] = 2.0 * h[n - 1];
    for (std::size_t k = 1; k <= n; ++k) {  // elimination below the diagonal
      const double w = lower[k] / diag[k - 1];
      diag[k] -= w * upper[k - 1];
      rhs[k] -= w * rhs[k - 1];
    }
    M[n] = rhs[n] / diag[n];
    for (std::size_t k = n; k-- > 0;) M[k] = (rhs[k] - upper[k] * M[k + 1]) / diag[k];
    b_.resize(n), c_.resize(n), d_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      b_[k] = s[k] - h[k] * (2.0 * M[k] + M[k + 1]) / 6.0;
      c_[k] = 0.5 * M[k];
      d_[k] = (M[k + 1] - M[k]) / (6.0 * h[k]);
    }
  }
};

using Path2 = TaskPath<2>;
using Path3 = TaskPath<3>;
using Profile1 = TaskPath<1>;

/// A planar path as a path in space: the same vertices with z = 0 [m], the same durations [s] and shape.
inline Path3 lift_to_3d(const Path2& path) {
  std::vector<Path3::Point> v;
  v.reserve(path.vertices().size());
  for (const auto& p : path.vertices()) v.emplace_back(p.x(), p.y(), 0.0);
  return Path3(std::move(v), path.durations(), path.shape());
}

/// The seed's square: (1.5, 1.5) -> (1.5, 2) -> (2, 2) -> (2, 1.5) -> (1.5, 1.5), 0.5 s per side.
inline Path2 seed_square() {
  return Path2({Eigen::Vector2d(1.5, 1.5), Eigen::Vector2d(1.5, 2.0), Eigen::Vector2d(2.0, 2.0),
                Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(1.5, 1.5)},
               {0.5, 0.5, 0.5, 0.5});
}

}  // namespace ks
