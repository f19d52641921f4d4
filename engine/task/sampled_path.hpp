#pragma once
// A path sampled the way the seed samples it: t_i = i dt for i = 0 .. n - 1, n = floor(T / dt) + 1,
// each sample on the segment QuinticPath::segment_at(t_i) picks (t <= 0.5 -> A, ...).
// Every run of a sweep follows the same path at the same dt, so the samples are computed once and
// shared read-only by all runs and threads; the simulation step then reads four numbers instead of
// choosing a segment and evaluating three quintics.
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "task/quintic_path.hpp"

namespace ks {

/// Number of samples the seed takes on a path of duration T [s] at step dt [s]: t = 0 : dt : T.
inline std::size_t sample_count(double duration, double dt) {
  return static_cast<std::size_t>(std::floor(duration / dt + 1e-9)) + 1;
}

class SampledPath {
 public:
  /// path: positions [m] over time [s]; dt > 0 [s] (std::invalid_argument otherwise, or for more
  /// than 1e8 samples: study files are checked for that before any run).
  SampledPath(Path2 path, double dt) : path_(std::move(path)), dt_(dt) {
    if (!(dt_ > 0) || !(path_.duration() / dt_ < 1e8))
      throw std::invalid_argument("SampledPath: dt = " + std::to_string(dt_) + " s on a " +
                                  std::to_string(path_.duration()) + " s path");
    const std::size_t n = sample_count(path_.duration(), dt_);
    xa_.resize(4 * n);
    segment_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double t = time(i);
      const std::size_t s = path_.segment_at(t);
      const PathSample<2> x = path_.sample_on(s, t);
      xa_[4 * i] = x.p.x();
      xa_[4 * i + 1] = x.p.y();
      xa_[4 * i + 2] = x.a.x();
      xa_[4 * i + 3] = x.a.y();
      segment_[i] = static_cast<std::uint32_t>(s);
    }
  }
  const Path2& path() const { return path_; }
  double dt() const { return dt_; }
  std::size_t size() const { return segment_.size(); }
  /// t_i [s], computed as the simulation loop computes it
  double time(std::size_t i) const { return static_cast<double>(i) * dt_; }
  /// position [m] and acceleration [m/s^2] of the path at t_i
  Eigen::Vector2d position(std::size_t i) const { return {xa_[4 * i], xa_[4 * i + 1]}; }
  Eigen::Vector2d acceleration(std::size_t i) const { return {xa_[4 * i + 2], xa_[4 * i + 3]}; }
  std::size_t segment(std::size_t i) const { return segment_[i]; }

 private:
  Path2 path_;
  double dt_;
  std::vector<double> xa_;               // x, y, xdd, ydd per sample
  std::vector<std::uint32_t> segment_;
};

}  // namespace ks
