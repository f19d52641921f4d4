#pragma once
// Internal: the memory of the journal driver's page overlay (journal_vfd.cpp). Only store/*.cpp.
#include <cstddef>
#include <vector>

#include "store/journal/format.hpp"

namespace ks::store::detail::journal {

/// The memory of the overlay's pages: blocks mapped for them alone (anonymous mmap), reused from
/// one commit to the next, and unmapped at a commit beyond the first kKeepBlocks. Pages allocated one
/// by one from malloc would stay, once freed, in the arena of whichever thread wrote them (a sweep
/// writes from any of its threads), each arena keeping the footprint of its largest overlay: the
/// resident memory then grew with the length of a sweep although the overlay never holds more than
/// the pages of one commit.
class PagePool {
 public:
  PagePool() = default;
  PagePool(const PagePool&) = delete;
  PagePool& operator=(const PagePool&) = delete;
  ~PagePool();
  /// kPage bytes, valid until reset(); nullptr when the system refuses memory.
  unsigned char* get();
  /// Takes every page back (they are invalid afterwards); unmaps the blocks beyond kKeepBlocks.
  void reset();

 private:
  static constexpr std::size_t kBlockPages = 256, kBlockBytes = kBlockPages * kPage;  // 1 MiB blocks
  /// Kept across commits: the overlay of a commit of the writer's usual size (it commits once 4 MiB
  /// of rows wait) plus the metadata HDF5 rewrites with them.
  static constexpr std::size_t kKeepBlocks = 8;
  std::vector<unsigned char*> blocks_;
  std::size_t block_ = 0, used_ = 0;  // the block pages are handed out of, and its pages handed out
};

}  // namespace ks::store::detail::journal
