#pragma once
// Seeded random joint states for property tests.
#include <Eigen/Core>
#include <random>

namespace ks::test {

struct RandomStates {
  std::mt19937_64 rng{20221123};
  std::uniform_real_distribution<double> angle{-3.14159, 3.14159};
  std::uniform_real_distribution<double> rate{-4.0, 4.0};
  Eigen::Vector3d q() { return {angle(rng), angle(rng), angle(rng)}; }
  Eigen::Vector3d v() { return {rate(rng), rate(rng), rate(rng)}; }
};

}  // namespace ks::test
