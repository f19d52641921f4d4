#pragma once
// Dense solves of small fixed-size systems for the IK solvers (ik/solve_impl.hpp): Eigen's
// PartialPivLU and LLT behind functions compiled once per size, in ik/small_dense.cpp, instead of in
// every file that instantiates a solver (each instance of Eigen's decompositions and their condition
// estimate costs seconds of compile time; the chain solvers need them for every joint count). The
// operations are Eigen's, unchanged, so the results are the same bits as calling Eigen directly:
// small_dense.cpp calls the unblocked factorisations that Eigen's PartialPivLU and LLT run for
// these sizes, without instantiating their blocked (dynamic-size) paths, which never run here.
//
//   SmallLu<N> lu(A);          // A = P^-1 L U, partial pivoting
//   Vec<N> x = lu.solve(b);    // A x = b
//   double r = lu_rcond<N>(A); // LAPACK-style estimate of 1 / (|A|_1 |A^-1|_1)
//   SmallLlt<N> llt(A);        // A = L L^T (A symmetric positive definite)
//   if (llt.ok()) x = llt.solve(b);
//
// Sizes: N = 2 .. kMaxSmallDense (8, the largest chain); other sizes fail to link.
#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "ik/problem.hpp"

namespace ks::ik {

inline constexpr int kMaxSmallDense = 8;

/// LU with partial pivoting of an N x N matrix (Eigen::PartialPivLU<Mat<N, N>>).
template <int N>
class SmallLu {
 public:
  /// \param[in] A (N x N) the matrix factorised.
  explicit SmallLu(const Mat<N, N>& A);
  /// \return x with A x = b (b: N entries).
  Vec<N> solve(const Vec<N>& b) const;
  /// \return X with A X = B (B: N x N).
  Mat<N, N> solve(const Mat<N, N>& B) const;

 private:
  Mat<N, N> lu_;                         // L (unit lower, below the diagonal) and U, as PartialPivLU's
  Eigen::PermutationMatrix<N, N> p_;     // P, as PartialPivLU's permutationP()
};

/// Cholesky factorisation A = L L^T of a symmetric N x N matrix (Eigen::LLT<Mat<N, N>>, lower).
template <int N>
class SmallLlt {
 public:
  /// \param[in] A (N x N, symmetric) the matrix factorised (its lower triangle is read).
  explicit SmallLlt(const Mat<N, N>& A);
  /// \return true when A was found positive definite (Eigen::Success).
  bool ok() const;
  /// \return x with A x = b (b: N entries); meaningful only when ok().
  Vec<N> solve(const Vec<N>& b) const;

 private:
  Mat<N, N> l_;  // L in the lower triangle, as LLT's matrixLLT()
  bool ok_;
};

/// Reciprocal condition estimate of A (N x N) in the 1-norm by its LU (Eigen's PartialPivLU::rcond, 0 when singular).
template <int N>
double lu_rcond(const Mat<N, N>& A);

#define KS_SMALL_DENSE_EXTERN(N)            \
  extern template class SmallLu<N>;         \
  extern template class SmallLlt<N>;        \
  extern template double lu_rcond<N>(const Mat<N, N>&);
KS_SMALL_DENSE_EXTERN(2)
KS_SMALL_DENSE_EXTERN(3)
KS_SMALL_DENSE_EXTERN(4)
KS_SMALL_DENSE_EXTERN(5)
KS_SMALL_DENSE_EXTERN(6)
KS_SMALL_DENSE_EXTERN(7)
KS_SMALL_DENSE_EXTERN(8)
#undef KS_SMALL_DENSE_EXTERN

}  // namespace ks::ik
