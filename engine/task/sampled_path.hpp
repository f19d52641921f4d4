#pragma once
// A path sampled the way the seed samples it: t_i = i dt for i = 0 .. n - 1, n = floor(T / dt) + 1,
// each sample on the segment TaskPath::segment_at(t_i) picks (t <= 0.5 -> A, ...).
// Every run of a sweep follows the same path at the same dt, so the samples are computed once and
// shared read-only by all runs and threads; the simulation step then reads 2 Dim numbers instead of
// choosing a segment and evaluating 3 Dim polynomials. Dim = 2: the planar arm's tip path
// (SampledPath); Dim = 3: a chain's tip path in space (SampledPath3).
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "task/task_path.hpp"

namespace ks {

/// Number of samples the seed takes on a path of duration T [s] at step dt [s]: t = 0 : dt : T.
inline std::size_t sample_count(double duration, double dt) {
  return static_cast<std::size_t>(std::floor(duration / dt + 1e-9)) + 1;
}

template <int Dim>
class SampledTaskPath {
 public:
  using Point = Eigen::Matrix<double, Dim, 1>;

  /// path: positions [m] over time [s]; dt > 0 [s] (std::invalid_argument otherwise, or for more
  /// than 1e8 samples: study files are checked for that before any run).
  SampledTaskPath(TaskPath<Dim> path, double dt) : path_(std::move(path)), dt_(dt) {
    if (!(dt_ > 0) || !(path_.duration() / dt_ < 1e8))
      throw std::invalid_argument("SampledPath: dt = " + std::to_string(dt_) + " s on a " +
                                  std::to_string(path_.duration()) + " s path");
    const std::size_t n = sample_count(path_.duration(), dt_);
    xa_.resize(2 * Dim * n);
    segment_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double t = time(i);
      const std::size_t s = path_.segment_at(t);
      const PathSample<Dim> x = path_.sample_on(s, t);
      for (int d = 0; d < Dim; ++d) {
        xa_[2 * Dim * i + d] = x.p[d];
        xa_[2 * Dim * i + Dim + d] = x.a[d];
      }
      segment_[i] = static_cast<std::uint32_t>(s);
    }
  }
  const TaskPath<Dim>& path() const { return path_; }
  double dt() const { return dt_; }
  std::size_t size() const { return segment_.size(); }
  /// t_i [s], computed as the simulation loop computes it
  double time(std::size_t i) const { return static_cast<double>(i) * dt_; }
  /// position [m] and acceleration [m/s^2] of the path at t_i
  Point position(std::size_t i) const { return Eigen::Map<const Point>(&xa_[2 * Dim * i]); }
  Point acceleration(std::size_t i) const { return Eigen::Map<const Point>(&xa_[2 * Dim * i + Dim]); }
  std::size_t segment(std::size_t i) const { return segment_[i]; }
  /// The samples as one array: position (Dim), then acceleration (Dim), per sample.
  const double* data() const { return xa_.data(); }
  /// The segment of every sample.
  const std::uint32_t* segments() const { return segment_.data(); }

 private:
  TaskPath<Dim> path_;
  double dt_;
  std::vector<double> xa_;               // position, then acceleration, per sample
  std::vector<std::uint32_t> segment_;
};

using SampledPath = SampledTaskPath<2>;
using SampledPath3 = SampledTaskPath<3>;

}  // namespace ks
