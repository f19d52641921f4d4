// ResultsWriter::copy_runs: the /runs rows of other results files of the same study (the shards of
// a distributed sweep) copied column by column, whole chunks as they are stored where one file
// holds every row of a chunk.
#include <hdf5.h>

#include <algorithm>
#include <cstring>
#include <numeric>

#include "store/writer_impl.hpp"

namespace ks::store {

using namespace detail;

namespace {

/// One source's /runs column datasets, in the writer's column order (empty when its layout differs).
std::vector<Hid> source_columns(const ResultsReader& src, hid_t file, const std::vector<ColumnSpec>& columns,
                                hsize_t chunk_rows, std::int64_t n_runs) {
  std::vector<Hid> out;
  if (src.meta().format_version < 4 || src.n_runs() != n_runs) return out;
  const std::vector<ColumnSpec>& theirs = src.columns();
  if (theirs.size() != columns.size()) return out;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (theirs[c].name != columns[c].name || theirs[c].type != columns[c].type || theirs[c].labels != columns[c].labels)
      return {};
    Hid d(H5Dopen2(file, ("runs/" + columns[c].name).c_str(), H5P_DEFAULT));
    if (!d.ok()) return {};
    Hid plist(H5Dget_create_plist(d));
    hsize_t dims = 0;
    if (H5Pget_layout(plist) != H5D_CHUNKED || H5Pget_chunk(plist, 1, &dims) != 1 || dims != chunk_rows) return {};
    out.push_back(std::move(d));
  }
  return out;
}

/// Rows [first, first + count) of a chunked column as its elements' bytes (the file's integer or
/// float type read natively: an enum's codes, a number's 8 bytes).
void read_range(hid_t dset, hsize_t first, hsize_t count, std::vector<unsigned char>& out, const std::string& path) {
  Hid fs(H5Dget_space(dset));
  H5Sselect_hyperslab(fs, H5S_SELECT_SET, &first, nullptr, &count, nullptr);
  Hid ms(H5Screate_simple(1, &count, nullptr));
  Hid ft(H5Dget_type(dset));
  Hid mt(H5Tget_native_type(ft, H5T_DIR_ASCEND));
  out.resize(count * H5Tget_size(mt));
  check(H5Dread(dset, mt, ms, fs, H5P_DEFAULT, out.data()), path, "read a shard's /runs rows");
}

}  // namespace

bool ResultsWriter::copy_runs(const std::vector<const ResultsReader*>& sources, const std::vector<std::int32_t>& owner,
                              int level) {
  QuietHdf5 quiet;
  Impl& m = *impl_;
  m.usable();
  m.touched = true;
  m.content = true;
  if (!m.runs_chunks.active() || std::any_of(m.chunk_col.begin(), m.chunk_col.end(), [](int c) { return c < 0; }))
    return false;
  const hsize_t cr = m.runs_chunks.chunk_rows();
  std::vector<std::vector<Hid>> src(sources.size());
  for (std::size_t s = 0; s < sources.size(); ++s) {
    src[s] = source_columns(*sources[s], static_cast<hid_t>(sources[s]->raw_file_id()), m.columns, cr, m.n_runs);
    if (src[s].empty()) return false;
  }
  std::vector<char> histories(sources.size());
  for (std::size_t s = 0; s < sources.size(); ++s) histories[s] = sources[s]->has_histories();
  const auto n = static_cast<hsize_t>(m.n_runs);
  const std::size_t n_cols = m.columns.size();
  std::vector<std::vector<hsize_t>> ids(sources.size());  // per source: its rows of the chunk
  std::vector<unsigned char> stored, range, picked;
  std::size_t copied_bytes = 0;
  for (hsize_t k = 0, lo = 0; lo < n; ++k, lo += cr) {
    const hsize_t hi = std::min(n, lo + cr);
    for (auto& v : ids) v.clear();
    std::size_t taken = 0, from = 0;
    for (hsize_t id = lo; id < hi; ++id) {
      const std::int32_t s = id < owner.size() ? owner[id] : -1;
      if (s < 0 || m.done[id]) continue;
      ids[static_cast<std::size_t>(s)].push_back(id);
      ++taken, from = static_cast<std::size_t>(s);
    }
    if (!taken) continue;
    // The chunk's histories first: the commit that counts a run done holds its history.
    for (std::size_t s = 0; s < ids.size(); ++s)
      if (histories[s])
        for (hsize_t id : ids[s])
          if (sources[s]->has_history(static_cast<std::int64_t>(id)))
            m.write_history(static_cast<std::int64_t>(id), sources[s]->read_history_chunks(static_cast<std::int64_t>(id), level));
    try {
      if (taken == hi - lo && ids[from].size() == taken && m.chunk_done[k] == 0) {
        // One source holds the whole chunk: its stored bytes (same filters, same chunk) as they are.
        for (std::size_t c = 0; c < n_cols; ++c) {
          hsize_t offset = lo, bytes = 0;
          std::uint32_t mask = 0;
          hid_t in = src[from][c];
          check(H5Dget_chunk_storage_size(in, &offset, &bytes), m.path, "size a shard's /runs chunk");
          stored.resize(bytes);
          check(H5Dread_chunk(in, H5P_DEFAULT, &offset, &mask, stored.data()), m.path, "read a shard's /runs chunk");
          check(H5Dwrite_chunk(m.col_dsets[c], H5P_DEFAULT, mask, &offset, bytes, stored.data()), m.path,
                "write a chunk of /runs");
          copied_bytes += bytes;
        }
      } else {
        // Rows from several sources (or some already here): each source's range of the chunk read
        // decoded, its rows put into the chunk's buffer, encoded once the chunk is complete.
        for (std::size_t c = 0; c < n_cols; ++c) {
          const auto col = static_cast<std::size_t>(m.chunk_col[c]);
          for (std::size_t s = 0; s < ids.size(); ++s) {
            if (ids[s].empty()) continue;
            const hsize_t first = ids[s].front(), count = ids[s].back() - first + 1;
            read_range(src[s][c], first, count, range, m.path);
            const std::size_t size = range.size() / count;
            picked.resize(ids[s].size() * size);
            for (std::size_t i = 0; i < ids[s].size(); ++i)
              std::memcpy(picked.data() + i * size, range.data() + (ids[s][i] - first) * size, size);
            m.runs_chunks.set(col, ids[s], picked.data());
            copied_bytes += picked.size();
          }
        }
      }
    } catch (const StoreError&) {
      m.fail("cannot copy the /runs rows of a shard");
    }
    if (taken == hi - lo && m.chunk_done[k] == 0) {  // the whole chunk, none of it here before
      std::fill(m.done.begin() + static_cast<std::ptrdiff_t>(lo), m.done.begin() + static_cast<std::ptrdiff_t>(hi), true);
      m.chunk_done[k] = static_cast<std::uint32_t>(hi - lo);
      const std::size_t at = m.unflagged.size();
      m.unflagged.resize(at + (hi - lo));
      std::iota(m.unflagged.begin() + static_cast<std::ptrdiff_t>(at), m.unflagged.end(), lo);
    } else {
      for (const auto& v : ids)
        for (hsize_t id : v) {
          m.mark_done(static_cast<std::int64_t>(id));
          m.unflagged.push_back(id);
        }
    }
    if (m.chunk_done[k] == hi - lo) {
      try {
        m.runs_chunks.write_complete({k});
      } catch (const StoreError&) {
        m.fail("cannot write the chunks of /runs");
      }
    }
    // Commit now and then: the journal holds the pages written since the last commit.
    if (copied_bytes >= (std::size_t{64} << 20)) {
      m.do_flush();
      copied_bytes = 0;
    }
  }
  return true;
}

}  // namespace ks::store
