// The two families of methods/path_global/alpha_basis.hpp and their least-squares fit.
#include "methods/path_global/alpha_basis.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <stdexcept>
#include <string>

namespace ks {
namespace {

/// Nonzero cubic B-spline basis functions N_{span-3..span} and their first two derivatives at t on
/// knot vector U (The NURBS Book, algorithm A2.3, degree 3, two derivatives): ders[d][j].
void cubic_basis_derivatives(const std::vector<double>& U, int span, double t, double (&ders)[3][4]) {
  constexpr int p = 3;
  double ndu[p + 1][p + 1], left[p + 1], right[p + 1];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[span + 1 - j];
    right[j] = U[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j) ders[0][j] = ndu[j][p];
  double a[2][p + 1];
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= 2; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k][r] = d;
      std::swap(s1, s2);
    }
  }
  double f = p;
  for (int k = 1; k <= 2; ++k) {
    for (int j = 0; j <= p; ++j) ders[k][j] *= f;
    f *= p - k;
  }
}

}  // namespace

AlphaBasis vertex_quintic_basis(const SampledPath& path) {
  const Path2& p = path.path();
  std::vector<Eigen::Matrix<double, 1, 1>> unit;  // the profile that is k at vertex k
  for (std::size_t k = 0; k <= p.segments(); ++k) unit.emplace_back(static_cast<double>(k));
  const Profile1 u(std::move(unit), p.durations());
  AlphaBasis b;
  b.coefficients = static_cast<int>(p.vertices().size());
  b.rows.resize(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    const std::size_t s = path.segment(i);
    const PathSample<1> x = u.sample_on(s, path.time(i));
    const double h = x.p[0] - static_cast<double>(s);  // the fraction of the segment's rise done
    BasisRow& r = b.rows[i];
    r.first = static_cast<int>(s);
    r.w[0][0] = 1.0 - h, r.w[0][1] = h;
    r.w[1][0] = -x.v[0], r.w[1][1] = x.v[0];
    r.w[2][0] = -x.a[0], r.w[2][1] = x.a[0];
  }
  return b;
}

AlphaBasis cubic_spline_basis(const SampledPath& path, int knots, bool rest_at_end) {
  return cubic_spline_basis(path.size(), path.dt(), path.path().duration(), knots, rest_at_end);
}

AlphaBasis cubic_spline_basis(std::size_t samples, double dt, double duration, int knots, bool rest_at_end) {
  if (knots < 2) throw std::invalid_argument("cubic_spline_basis: knots = " + std::to_string(knots) + "; expected >= 2");
  const double T = duration;
  const int m = knots + 2;  // control points
  std::vector<double> U(4, 0.0);
  for (int j = 1; j + 1 < knots; ++j) U.push_back(T * j / (knots - 1));
  U.insert(U.end(), 4, T);
  // control point j -> coefficient: the first two tied (zero rate at the start), and the last two
  // when the end is at rest
  const int count = rest_at_end ? knots : knots + 1;
  const auto coefficient = [count](int j) { return std::clamp(j - 1, 0, count - 1); };
  AlphaBasis b;
  b.coefficients = count;
  b.rows.resize(samples);
  for (std::size_t i = 0; i < samples; ++i) {
    const double t = std::clamp(static_cast<double>(i) * dt, 0.0, T);  // SampledTaskPath::time
    int span = 3;
    while (span < m - 1 && t >= U[span + 1]) ++span;
    double ders[3][4];
    cubic_basis_derivatives(U, span, t, ders);
    BasisRow& r = b.rows[i];
    r.first = coefficient(span - 3);
    for (int j = 0; j < 4; ++j) {
      const int k = coefficient(span - 3 + j) - r.first;
      for (int d = 0; d < 3; ++d) r.w[d][k] += ders[d][j];
    }
  }
  return b;
}

std::vector<double> fit_basis(const AlphaBasis& basis, const double* alpha, std::size_t count) {
  count = std::min(count, basis.rows.size());
  const int K = basis.coefficients;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(count), K);
  for (std::size_t i = 0; i < count; ++i) {
    const BasisRow& r = basis.rows[i];
    for (int k = 0; k < kBasisWidth && r.first + k < K; ++k) A(static_cast<Eigen::Index>(i), r.first + k) = r.w[0][k];
  }
  std::vector<int> used;
  for (int k = 0; k < K; ++k)
    if (A.col(k).cwiseAbs().maxCoeff() > 1e-12) used.push_back(k);
  std::vector<double> c(K, 0.0);
  if (used.empty()) return c;
  Eigen::MatrixXd Au(A.rows(), static_cast<Eigen::Index>(used.size()));
  for (std::size_t k = 0; k < used.size(); ++k) Au.col(static_cast<Eigen::Index>(k)) = A.col(used[k]);
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(alpha, static_cast<Eigen::Index>(count));
  const Eigen::VectorXd x = Au.colPivHouseholderQr().solve(y);
  double last = x[0];
  for (int k = 0, u = 0; k < K; ++k) {
    if (u < static_cast<int>(used.size()) && used[u] == k) last = x[u++];
    c[k] = last;
  }
  return c;
}

}  // namespace ks
