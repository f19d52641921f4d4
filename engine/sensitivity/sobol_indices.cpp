#include "sensitivity/sobol_indices.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace ks {

bool SobolOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  if (bootstrap < 0) return fail("bootstrap must be >= 0");
  if (!(confidence > 0.0 && confidence < 1.0)) return fail("confidence must lie in (0, 1)");
  return true;
}

namespace {

/// The indices from the rows `rows` of the kept sample rows (a, b, ab already filtered).
void estimate(const std::vector<double>& a, const std::vector<double>& b, const std::vector<std::vector<double>>& ab,
              const std::vector<std::uint32_t>& rows, std::vector<double>& first, std::vector<double>& total,
              double& variance) {
  const double n = static_cast<double>(rows.size());
  double mean = 0.0;
  for (std::uint32_t j : rows) mean += a[j] + b[j];
  mean /= 2.0 * n;
  double v = 0.0;
  for (std::uint32_t j : rows) v += (a[j] - mean) * (a[j] - mean) + (b[j] - mean) * (b[j] - mean);
  v /= 2.0 * n - 1.0;
  variance = v;
  first.assign(ab.size(), std::nan(""));
  total.assign(ab.size(), std::nan(""));
  if (!(v > 0.0)) return;
  for (std::size_t i = 0; i < ab.size(); ++i) {
    double s1 = 0.0, st = 0.0;
    for (std::uint32_t j : rows) {
      s1 += (b[j] - mean) * (ab[i][j] - a[j]);  // centred: the same expectation, less variance
      st += (a[j] - ab[i][j]) * (a[j] - ab[i][j]);
    }
    first[i] = s1 / n / v;
    total[i] = st / (2.0 * n) / v;
  }
}

/// The q-quantile of `v` (sorted in place), linear between order statistics.
double quantile(std::vector<double>& v, double q) {
  std::sort(v.begin(), v.end());
  const double at = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(at));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (at - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

}  // namespace

SobolIndices sobol_indices(std::span<const double> a, std::span<const double> b,
                           const std::vector<std::span<const double>>& ab, const SobolOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument("sobol_indices: " + why);
  const std::size_t n = a.size(), d = ab.size();
  if (b.size() != n || std::any_of(ab.begin(), ab.end(), [&](auto s) { return s.size() != n; }))
    throw std::invalid_argument("sobol_indices: f(A), f(B) and every f(AB_i) need the same number of rows");
  if (n > UINT32_MAX) throw std::invalid_argument("sobol_indices: more than 2^32 sample rows");
  // The rows whose d + 2 values are all finite.
  std::vector<double> ka, kb;
  std::vector<std::vector<double>> kab(d);
  SobolIndices out;
  for (std::size_t j = 0; j < n; ++j) {
    bool finite = std::isfinite(a[j]) && std::isfinite(b[j]);
    for (std::size_t i = 0; i < d && finite; ++i) finite = std::isfinite(ab[i][j]);
    if (!finite) {
      ++out.dropped;
      continue;
    }
    ka.push_back(a[j]);
    kb.push_back(b[j]);
    for (std::size_t i = 0; i < d; ++i) kab[i].push_back(ab[i][j]);
  }
  out.samples = ka.size();
  const auto nan = std::nan("");
  out.first_lo = out.first_hi = out.total_lo = out.total_hi = std::vector<double>(d, nan);
  if (out.samples < 2) {
    out.first = out.total = std::vector<double>(d, nan);
    out.variance = nan;
    return out;
  }
  std::vector<std::uint32_t> rows(out.samples);
  for (std::uint32_t j = 0; j < rows.size(); ++j) rows[j] = j;
  estimate(ka, kb, kab, rows, out.first, out.total, out.variance);
  if (options.bootstrap == 0) return out;
  // Percentile intervals over resamples of the rows (with replacement).
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(rows.size() - 1));
  std::vector<std::vector<double>> s1(d), st(d);
  std::vector<double> f, t;
  double v = 0.0;
  for (int r = 0; r < options.bootstrap; ++r) {
    for (auto& j : rows) j = pick(rng);
    estimate(ka, kb, kab, rows, f, t, v);
    for (std::size_t i = 0; i < d; ++i) s1[i].push_back(f[i]), st[i].push_back(t[i]);
  }
  const double q = (1.0 - options.confidence) / 2.0;
  for (std::size_t i = 0; i < d; ++i) {
    std::erase_if(s1[i], [](double x) { return !std::isfinite(x); });
    std::erase_if(st[i], [](double x) { return !std::isfinite(x); });
    if (!s1[i].empty()) out.first_lo[i] = quantile(s1[i], q), out.first_hi[i] = quantile(s1[i], 1.0 - q);
    if (!st[i].empty()) out.total_lo[i] = quantile(st[i], q), out.total_hi[i] = quantile(st[i], 1.0 - q);
  }
  return out;
}

}  // namespace ks
