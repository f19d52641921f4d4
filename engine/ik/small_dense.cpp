// SmallLu and SmallLlt (ik/small_dense.hpp), compiled once for N = 2 .. kMaxSmallDense.
//
// Each function runs the same Eigen code as Eigen::PartialPivLU<Mat<N, N>> and Eigen::LLT<Mat<N, N>>
// (Eigen 3.4) for these sizes, step for step: the factorisations call the unblocked kernels that
// PartialPivLU's blocked_lu (unblocked at compile time for sizes up to 16) and LLT's blocked (below
// 32 at run time) hand over to, and the solves are those of their _solve_impl. Going through the
// classes themselves would instantiate their blocked paths (general matrix products and triangular
// solves on dynamic blocks) for every size: most of this file's compile time, for code that never runs.
#include "ik/small_dense.hpp"

namespace ks::ik {
namespace {

/// What Eigen's condition estimator (internal::rcond_estimate_helper) asks of a decomposition: the
/// solves of PartialPivLU (_solve_impl, _solve_impl_transposed<false>) on an LU and its permutation.
template <int N>
struct LuView {
  using MatrixType = Mat<N, N>;
  using Scalar = double;
  using RealScalar = double;
  const Mat<N, N>& lu;
  const Eigen::PermutationMatrix<N, N>& p;

  Eigen::Index rows() const { return N; }
  Eigen::Index cols() const { return N; }
  template <class Rhs>
  Vec<N> solve(const Rhs& rhs) const {
    Vec<N> dst;
    dst = p * rhs;
    lu.template triangularView<Eigen::UnitLower>().solveInPlace(dst);
    lu.template triangularView<Eigen::Upper>().solveInPlace(dst);
    return dst;
  }
  struct Adjoint {
    const LuView& d;
    template <class Rhs>
    Vec<N> solve(const Rhs& rhs) const {
      Vec<N> dst;
      dst = d.lu.template triangularView<Eigen::Upper>().transpose().solve(rhs);
      d.lu.template triangularView<Eigen::UnitLower>().transpose().solveInPlace(dst);
      dst = d.p.transpose() * dst;
      return dst;
    }
  };
  Adjoint adjoint() const { return Adjoint{*this}; }
};

/// PartialPivLU::compute's factorisation of lu (in place) into lu and p.
template <int N>
void lu_factor(Mat<N, N>& lu, Eigen::PermutationMatrix<N, N>& p) {
  using Impl = Eigen::internal::partial_lu_impl<double, Eigen::ColMajor, int, N>;
  static_assert(Impl::UnBlockedAtCompileTime, "Eigen factorises this size unblocked");
  Eigen::Transpositions<N, N, int> rows_transpositions;
  int nb_transpositions = 0;
  typename Impl::MatrixTypeRef ref(lu);
  Impl::unblocked_lu(ref, &rows_transpositions.coeffRef(0), nb_transpositions);
  p = rows_transpositions;
}

}  // namespace

template <int N>
SmallLu<N>::SmallLu(const Mat<N, N>& A) : lu_(A) {
  lu_factor<N>(lu_, p_);
}

template <int N>
Vec<N> SmallLu<N>::solve(const Vec<N>& b) const {
  return LuView<N>{lu_, p_}.solve(b);
}

template <int N>
Mat<N, N> SmallLu<N>::solve(const Mat<N, N>& B) const {
  Mat<N, N> X;
  X = p_ * B;
  lu_.template triangularView<Eigen::UnitLower>().solveInPlace(X);
  lu_.template triangularView<Eigen::Upper>().solveInPlace(X);
  return X;
}

template <int N>
SmallLlt<N>::SmallLlt(const Mat<N, N>& A) : l_(A) {
  static_assert(N < 32, "Eigen's LLT factorises this size unblocked");
  ok_ = Eigen::internal::llt_inplace<double, Eigen::Lower>::unblocked(l_) == -1;
}

template <int N>
bool SmallLlt<N>::ok() const {
  return ok_;
}

template <int N>
Vec<N> SmallLlt<N>::solve(const Vec<N>& b) const {
  using Traits = Eigen::internal::LLT_Traits<Mat<N, N>, Eigen::Lower>;
  Vec<N> x = b;
  Traits::getL(l_).solveInPlace(x);
  Traits::getU(l_).solveInPlace(x);
  return x;
}

template <int N>
double lu_rcond(const Mat<N, N>& A) {
  const double l1_norm = A.cwiseAbs().colwise().sum().maxCoeff();
  Mat<N, N> lu = A;
  Eigen::PermutationMatrix<N, N> p;
  lu_factor<N>(lu, p);
  return Eigen::internal::rcond_estimate_helper(l1_norm, LuView<N>{lu, p});
}

#define KS_SMALL_DENSE_INSTANTIATE(N) \
  template class SmallLu<N>;          \
  template class SmallLlt<N>;         \
  template double lu_rcond<N>(const Mat<N, N>&);
KS_SMALL_DENSE_INSTANTIATE(2)
KS_SMALL_DENSE_INSTANTIATE(3)
KS_SMALL_DENSE_INSTANTIATE(4)
KS_SMALL_DENSE_INSTANTIATE(5)
KS_SMALL_DENSE_INSTANTIATE(6)
KS_SMALL_DENSE_INSTANTIATE(7)
KS_SMALL_DENSE_INSTANTIATE(8)
static_assert(kMaxSmallDense == 8, "instantiate every size up to kMaxSmallDense");

}  // namespace ks::ik
