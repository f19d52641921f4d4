// The journal overlay's page blocks (journal_pages.hpp).
#include "store/journal/pages.hpp"

#include <sys/mman.h>

namespace ks::store::detail::journal {

PagePool::~PagePool() {
  for (unsigned char* b : blocks_) ::munmap(b, kBlockBytes);
}

unsigned char* PagePool::get() {
  if (used_ == kBlockPages) ++block_, used_ = 0;
  if (block_ == blocks_.size()) {
    void* b = ::mmap(nullptr, kBlockBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (b == MAP_FAILED) return nullptr;
    blocks_.push_back(static_cast<unsigned char*>(b));
  }
  return blocks_[block_] + kPage * used_++;
}

void PagePool::reset() {
  while (blocks_.size() > kKeepBlocks) {
    ::munmap(blocks_.back(), kBlockBytes);
    blocks_.pop_back();
  }
  block_ = used_ = 0;
}

}  // namespace ks::store::detail::journal
