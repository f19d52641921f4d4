#pragma once
// Internal: the fixed-size /runs columns of a format 4 file (numbers and labels), written chunk by
// chunk (FORMAT.md, /runs). Only store/*.cpp.
//
// Rows are gathered per chunk in memory. A chunk whose rows are all written is encoded once
// (HDF5's shuffle then deflate, by libdeflate, when that saves at least a tenth of its bytes; its
// shuffled bytes as stored deflate blocks otherwise) and written with H5Dwrite_chunk. At a commit
// the chunks still incomplete are written stored, so the commit holds every row written; the next
// row of such a chunk reads it back first. Each chunk is thus compressed once, when it is complete.
#include <hdf5.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "store/h5util.hpp"
#include "store/store.hpp"

namespace ks::store::detail {

/// The chunk encoding of `n` elements of `size` bytes (1, 2 or 8) for the filters shuffle then
/// deflate (filter mask 0): with `compress`, deflated by libdeflate at `level` when that is at most
/// 0.9 of the raw bytes; otherwise the shuffled bytes in stored blocks (a zlib stream that inflates
/// by a copy).
EncodedChunk encode_column_chunk(const unsigned char* bytes, std::size_t n, std::size_t size, bool compress,
                                 int level = 1);

class RunsChunks {
 public:
  /// `dsets`: the chunked column datasets (chunks of `chunk_rows` rows, `n_rows` rows each), with the
  /// element size in the file of each; `done_rows`: per chunk, how many of its rows are written.
  void open(std::vector<hid_t> dsets, std::vector<std::size_t> sizes, hsize_t chunk_rows, hsize_t n_rows,
            const std::string& path);
  bool active() const { return chunk_rows_ > 0; }
  hsize_t chunk_rows() const { return chunk_rows_; }
  /// Sets column `col`'s rows `ids` (ascending) to `values` (file bytes, size(col) each).
  void set(std::size_t col, const std::vector<hsize_t>& ids, const unsigned char* values);
  /// Encodes and writes the buffered chunks in `complete` (their rows all written) for every
  /// column, and forgets them.
  void write_complete(const std::vector<hsize_t>& complete);
  /// Writes every buffered chunk changed since the last call raw (before a commit or a read);
  /// forgets those not changed since the call before (bounded memory on scattered writes).
  void write_partial();
  void clear() { chunks_.clear(); dsets_.clear(); }

 private:
  struct Chunk {
    ByteBuffer bytes;
    bool dirty = false, recent = true;
  };
  Chunk& chunk(std::size_t col, hsize_t index);
  void write_chunk(std::size_t col, hsize_t index, const EncodedChunk& e);
  std::vector<hid_t> dsets_;
  std::vector<std::size_t> sizes_;
  hsize_t chunk_rows_ = 0, n_rows_ = 0;
  std::string path_;
  std::vector<std::map<hsize_t, Chunk>> chunks_;  // per column: chunk index -> its rows
};

}  // namespace ks::store::detail
