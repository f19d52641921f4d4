// The block cache behind ByteBuffer (store.hpp: ByteAllocator).
#include <array>
#include <bit>
#include <mutex>
#include <new>
#include <vector>

#include "store/store.hpp"

namespace ks::store::detail {

namespace {
constexpr std::size_t kSmallest = std::size_t{16} << 10;  // below: plain operator new
constexpr int kClasses = 11;                               // 16 KiB .. 16 MiB
constexpr std::size_t kKeep = std::size_t{64} << 20;       // freed bytes kept at most

struct Cache {
  std::mutex m;
  std::array<std::vector<void*>, kClasses> free;
  std::size_t kept = 0;
};
/// Never destroyed: threads may free their buffers after static destructors ran.
Cache& cache() {
  static Cache* c = new Cache;
  return *c;
}

/// The size class of n bytes (-1: not cached) and its block size.
int size_class(std::size_t n, std::size_t& block) {
  if (n < kSmallest) return -1;
  block = std::bit_ceil(n);
  const int k = std::countr_zero(block) - std::countr_zero(kSmallest);
  return k < kClasses ? k : -1;
}
}  // namespace

void* byte_buffer_allocate(std::size_t n) {
  std::size_t block = n;
  const int k = size_class(n, block);
  if (k < 0) return ::operator new(n);
  Cache& c = cache();
  {
    std::lock_guard lock(c.m);
    if (!c.free[k].empty()) {
      void* p = c.free[k].back();
      c.free[k].pop_back();
      c.kept -= block;
      return p;
    }
  }
  return ::operator new(block);
}

void byte_buffer_deallocate(void* p, std::size_t n) noexcept {
  std::size_t block = n;
  const int k = size_class(n, block);
  if (k >= 0) {
    Cache& c = cache();
    std::lock_guard lock(c.m);
    if (c.kept + block <= kKeep) {
      try {
        c.free[k].push_back(p);
        c.kept += block;
        return;
      } catch (const std::bad_alloc&) {  // no room to list it: free it
      }
    }
  }
  ::operator delete(p);
}

}  // namespace ks::store::detail
