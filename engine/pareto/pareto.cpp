// Pareto fronts and hypervolume (pareto/pareto.hpp). Every objective is turned into one to minimise
// (a maximised one negated) before the sort.
#include "pareto/pareto.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace ks::pareto {

namespace {

using Point = std::array<double, 3>;

void check(std::size_t dims, std::span<const Sense> senses) {
  if (dims != 2 && dims != 3) throw std::invalid_argument("pareto: 2 or 3 objectives, not " + std::to_string(dims));
  if (senses.size() != dims) throw std::invalid_argument("pareto: one sense per objective");
}

/// The points without NaN, each objective turned into one to minimise, with their indices.
void minimised(std::span<const double> values, std::size_t dims, std::span<const Sense> senses,
               std::span<const std::uint8_t> eligible, std::vector<Point>& pts, std::vector<std::size_t>& index) {
  if (values.size() % dims != 0) throw std::invalid_argument("pareto: values are not whole points");
  const std::size_t n = values.size() / dims;
  if (!eligible.empty() && eligible.size() != n)
    throw std::invalid_argument("pareto: " + std::to_string(eligible.size()) + " eligibility flags for " +
                                std::to_string(n) + " points");
  for (std::size_t i = 0; i < n; ++i) {
    if (!eligible.empty() && !eligible[i]) continue;
    Point p{0, 0, 0};
    bool nan = false;
    for (std::size_t k = 0; k < dims; ++k) {
      const double v = values[i * dims + k];
      nan = nan || std::isnan(v);
      p[k] = senses[k] == Sense::max ? -v : v;
    }
    if (nan) continue;
    pts.push_back(p);
    index.push_back(i);
  }
}

bool dominates_min(const Point& a, const Point& b, std::size_t dims) {
  bool strict = false;
  for (std::size_t k = 0; k < dims; ++k) {
    if (a[k] > b[k]) return false;
    strict = strict || a[k] < b[k];
  }
  return strict;
}

/// Area dominated by `pts` (minimised, each strictly below `ref`) up to `ref`: sweep in x ascending,
/// each point adding the strip between its y and the lowest y seen so far.
double area(std::vector<Point> pts, double rx, double ry) {
  std::sort(pts.begin(), pts.end(), [](const Point& a, const Point& b) { return a[0] != b[0] ? a[0] < b[0] : a[1] < b[1]; });
  double total = 0, y_bound = ry;
  for (const Point& p : pts) {
    if (p[1] >= y_bound) continue;
    total += (rx - p[0]) * (y_bound - p[1]);
    y_bound = p[1];
  }
  return total;
}

}  // namespace

bool dominates(std::span<const double> a, std::span<const double> b, std::span<const Sense> senses) {
  bool strict = false;
  for (std::size_t k = 0; k < senses.size(); ++k) {
    const double x = senses[k] == Sense::max ? -a[k] : a[k], y = senses[k] == Sense::max ? -b[k] : b[k];
    if (!(x <= y)) return false;  // NaN: no domination
    strict = strict || x < y;
  }
  return strict;
}

std::vector<std::size_t> front(std::span<const double> values, std::size_t dims, std::span<const Sense> senses,
                               std::span<const std::uint8_t> eligible) {
  check(dims, senses);
  std::vector<Point> pts;
  std::vector<std::size_t> index;
  minimised(values, dims, senses, eligible, pts, index);
  std::vector<std::size_t> order(pts.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  // Lexicographic order: a point can only be dominated by one before it (a dominator is <= in every
  // coordinate and differs in one, so it sorts first); equal points sort together.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return pts[a] < pts[b]; });
  std::vector<std::size_t> out;
  if (dims == 2) {
    // Groups of equal x: within one, only the points of the lowest y (all equal) can be on the front,
    // and they are when that y is below the lowest y of every smaller x.
    double best_y = INFINITY;
    for (std::size_t g = 0; g < order.size();) {
      std::size_t end = g;
      while (end < order.size() && pts[order[end]][0] == pts[order[g]][0]) ++end;
      const double y0 = pts[order[g]][1];
      if (y0 < best_y) {
        for (std::size_t j = g; j < end && pts[order[j]][1] == y0; ++j) out.push_back(index[order[j]]);
        best_y = y0;
      }
      g = end;
    }
  } else {
    // Each point against the front so far: a dominated dominator is itself dominated by a front point
    // that sorts earlier, which dominates the point too.
    std::vector<std::size_t> kept;
    for (std::size_t o : order) {
      const bool dominated =
          std::any_of(kept.begin(), kept.end(), [&](std::size_t f) { return dominates_min(pts[f], pts[o], 3); });
      if (!dominated) kept.push_back(o);
    }
    for (std::size_t o : kept) out.push_back(index[o]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

double hypervolume(std::span<const double> values, std::size_t dims, std::span<const Sense> senses,
                   std::span<const double> ref) {
  check(dims, senses);
  if (ref.size() != dims) throw std::invalid_argument("pareto: the reference point needs one value per objective");
  Point r{0, 0, 0};
  for (std::size_t k = 0; k < dims; ++k) {
    if (std::isnan(ref[k])) throw std::invalid_argument("pareto: the reference point holds NaN");
    r[k] = senses[k] == Sense::max ? -ref[k] : ref[k];
  }
  std::vector<Point> all, pts;
  std::vector<std::size_t> index;
  minimised(values, dims, senses, {}, all, index);
  for (const Point& p : all) {
    bool inside = true;
    for (std::size_t k = 0; k < dims; ++k) inside = inside && p[k] < r[k];
    if (inside) pts.push_back(p);
  }
  if (dims == 2) return area(std::move(pts), r[0], r[1]);
  // Slices along z: between consecutive z values (and the last one and ref z) the cross-section is
  // the area dominated by the points of z at or below the slice's bottom.
  std::sort(pts.begin(), pts.end(), [](const Point& a, const Point& b) { return a[2] < b[2]; });
  double total = 0;
  std::vector<Point> below;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    below.push_back(pts[i]);
    const double top = i + 1 < pts.size() ? pts[i + 1][2] : r[2];
    if (top > pts[i][2]) total += area(below, r[0], r[1]) * (top - pts[i][2]);
  }
  return total;
}

}  // namespace ks::pareto
