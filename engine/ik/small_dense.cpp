// SmallLu and SmallLlt (ik/small_dense.hpp), compiled once for N = 2 .. kMaxSmallDense.
#include "ik/small_dense.hpp"

namespace ks::ik {

template <int N>
SmallLu<N>::SmallLu(const Mat<N, N>& A) : lu_(A) {}

template <int N>
Vec<N> SmallLu<N>::solve(const Vec<N>& b) const {
  return lu_.solve(b);
}

template <int N>
Mat<N, N> SmallLu<N>::solve(const Mat<N, N>& B) const {
  return lu_.solve(B);
}

template <int N>
SmallLlt<N>::SmallLlt(const Mat<N, N>& A) : llt_(A) {}

template <int N>
bool SmallLlt<N>::ok() const {
  return llt_.info() == Eigen::Success;
}

template <int N>
Vec<N> SmallLlt<N>::solve(const Vec<N>& b) const {
  return llt_.solve(b);
}

template <int N>
double lu_rcond(const Mat<N, N>& A) {
  return Eigen::PartialPivLU<Mat<N, N>>(A).rcond();
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
