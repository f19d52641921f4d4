// The Saltelli design of a sensitivity study (space.hpp: saltelli_draws).
#include <boost/random/sobol.hpp>
#include <cmath>
#include <random>
#include <stdexcept>

#include "space/space.hpp"

namespace ks {

std::vector<std::vector<double>> saltelli_draws(std::uint64_t seed, std::uint64_t count,
                                                std::span<const std::pair<double, double>> ranges) {
  const std::size_t d = ranges.size();
  if (d == 0 || count == 0) return std::vector<std::vector<double>>(d);
  if (d > 1000) throw std::invalid_argument("saltelli_draws: more than 1000 factors");
  // Points of the 2d-dimensional Sobol' sequence (the origin skipped), each coordinate shifted by a
  // uniform draw of `seed` modulo 1 (a Cranley-Patterson rotation): columns 0..d-1 are matrix A,
  // d..2d-1 matrix B.
  boost::random::sobol sobol(2 * d);
  sobol.discard(2 * d);
  std::mt19937_64 rng(seed);
  std::vector<double> shift(2 * d);
  for (double& s : shift) s = unit_open01(rng());
  std::vector<double> a(count * d), b(count * d);
  for (std::uint64_t j = 0; j < count; ++j)
    for (std::size_t k = 0; k < 2 * d; ++k) {
      double u = static_cast<double>(sobol() >> 11) * 0x1p-53 + shift[k];
      u -= std::floor(u);
      (k < d ? a[j * d + k] : b[j * d + k - d]) = u;
    }
  const std::uint64_t rows = count * (d + 2);
  std::vector<std::vector<double>> out(d, std::vector<double>(rows));
  for (std::size_t i = 0; i < d; ++i) {
    const double from = ranges[i].first, to = ranges[i].second;  // named, not bound: clang 14 captures no structured binding
    const auto at = [&](double u) { return from + (to - from) * u; };
    std::vector<double>& v = out[i];
    for (std::uint64_t j = 0; j < count; ++j) {
      v[j] = at(a[j * d + i]);          // A
      v[count + j] = at(b[j * d + i]);  // B
      for (std::size_t m = 0; m < d; ++m)  // AB_m: A with column m from B
        v[(2 + m) * count + j] = at(m == i ? b[j * d + i] : a[j * d + i]);
    }
  }
  return out;
}

}  // namespace ks
