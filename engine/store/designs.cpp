// /designs (FORMAT.md): the blocks run as a Saltelli design, written with the file and read back; and
// the dimension scale of /runs.
#include <hdf5.h>
#include <hdf5_hl.h>  // H5DS: dimension scales

#include "store/h5util.hpp"
#include "store/runs_read.hpp"
#include "store/reader_impl.hpp"
#include "store/store.hpp"

namespace ks::store {
namespace detail {

void attach_run_scale(hid_t runs, const std::string& path) {
  if (!link_exists(runs, "run_id")) return;  // (a table without run ids: tests of the store)
  Hid id(check(H5Dopen2(runs, "run_id", H5P_DEFAULT), path, "open /runs/run_id"));
  if (H5DSset_scale(id, "run_id") < 0) throw StoreError(path, "cannot make /runs/run_id a dimension scale");
  for (const std::string& name : read_str_list_attr(runs, "columns")) {
    if (name == "run_id") continue;
    Hid d(check(H5Dopen2(runs, name.c_str(), H5P_DEFAULT), path, "open /runs/" + name));
    if (H5DSattach_scale(d, id, 0) < 0) throw StoreError(path, "cannot attach run_id to /runs/" + name);
  }
  Hid done(check(H5Dopen2(runs, "done", H5P_DEFAULT), path, "open /runs/done"));
  if (H5DSattach_scale(done, id, 0) < 0) throw StoreError(path, "cannot attach run_id to /runs/done");
}

void write_designs(hid_t file, const std::vector<DesignMeta>& designs, const std::string& path) {
  if (designs.empty()) return;
  Hid root(check(H5Gcreate2(file, "designs", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /designs"));
  for (const DesignMeta& d : designs) {
    Hid g(check(H5Gcreate2(root, d.block.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), path, "create /designs/" + d.block));
    write_str_attr(g, "kind", d.kind);
    write_str_attr(g, "design", d.design);
    write_str_list_attr(g, "factors", d.factors);
    write_i64_attr(g, "base_samples", d.base_samples);
    write_i64_attr(g, "first_run", d.first_run);
    write_str_list_attr(g, "dims", d.dims);
    write_i64_list_attr(g, "sizes", d.sizes);
    write_i64_attr(g, "dim", d.dim);
  }
}

}  // namespace detail

using namespace detail;

namespace {
herr_t collect(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}

/// Throws StoreError naming /designs/<block> unless the design's rows [first_run, first_run +
/// prod(sizes)) lie inside /runs and are the rows of its block: run_id equal to the row at both
/// ends, the block column equal to the design's name at both ends and different just outside them
/// (a design shifted within its block, or onto another block's rows, reads other runs).
void check_design_rows(hid_t file, const std::string& path, std::int64_t n_runs,
                       const std::vector<ColumnSpec>& columns, const DesignMeta& d) {
  const std::string obj = "/designs/" + d.block;
  std::int64_t runs = 1;
  for (std::int64_t s : d.sizes) {
    if (s < 1 || runs > n_runs / s)
      throw StoreError(path, obj + ": sizes do not fit the " + std::to_string(n_runs) + " rows of /runs");
    runs *= s;
  }
  if (d.first_run < 0 || d.first_run > n_runs - runs)
    throw StoreError(path, obj + ": rows " + std::to_string(d.first_run) + ".." +
                                 std::to_string(d.first_run + runs - 1) + " (first_run, sizes) lie outside the " +
                                 std::to_string(n_runs) + " rows of /runs");
  const std::int64_t last = d.first_run + runs - 1;
  const auto has = [&](const char* name, CellType t) {
    for (const ColumnSpec& c : columns)
      if (c.name == name) return c.type == t;
    return false;
  };
  if (has("run_id", CellType::i64))
    for (std::int64_t row : {d.first_run, last}) {
      const auto id = read_runs_column<std::int64_t>(file, path, "run_id", H5T_NATIVE_INT64,
                                                     {static_cast<hsize_t>(row), 1});
      if (id.size() != 1 || id[0] != row)
        throw StoreError(path, obj + ": /runs/run_id of row " + std::to_string(row) + " is not " + std::to_string(row));
    }
  if (!has("block", CellType::str)) return;
  const auto block_at = [&](std::int64_t row) {
    return read_runs_strings(file, path, "block", {static_cast<hsize_t>(row), 1}).at(0);
  };
  for (std::int64_t row : {d.first_run, last})
    if (block_at(row) != d.block)
      throw StoreError(path, obj + ": row " + std::to_string(row) + " of /runs belongs to block '" + block_at(row) +
                                   "', not to the design's block (first_run " + std::to_string(d.first_run) + ")");
  for (std::int64_t row : {d.first_run - 1, last + 1})
    if (row >= 0 && row < n_runs && block_at(row) == d.block)
      throw StoreError(path, obj + ": row " + std::to_string(row) + " of /runs also belongs to block '" + d.block +
                                   "': the design (first_run " + std::to_string(d.first_run) + ", " +
                                   std::to_string(runs) + " rows) does not cover its block's rows");
}
}  // namespace

std::vector<DesignMeta> ResultsReader::designs() const {
  QuietHdf5 quiet;
  std::vector<DesignMeta> out;
  if (!link_exists(impl_->file, "designs")) return out;
  Hid root(check(H5Gopen2(impl_->file, "designs", H5P_DEFAULT), impl_->path, "open /designs"));
  std::vector<std::string> names;
  H5Literate(root, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect, &names);
  for (const std::string& name : names) {
    Hid g(check(H5Gopen2(root, name.c_str(), H5P_DEFAULT), impl_->path, "open /designs/" + name));
    DesignMeta d;
    d.block = name;
    d.kind = read_str_attr(g, "kind");
    d.design = read_str_attr(g, "design");
    d.factors = read_str_list_attr(g, "factors");
    d.base_samples = read_i64_attr(g, "base_samples", 0);
    d.first_run = read_i64_attr(g, "first_run", 0);
    d.dims = read_str_list_attr(g, "dims");
    d.sizes = read_i64_list_attr(g, "sizes");
    d.dim = read_i64_attr(g, "dim", 0);
    if (d.dims.size() != d.sizes.size() || d.dim < 0 || static_cast<std::size_t>(d.dim) >= d.dims.size() ||
        d.base_samples < 1 || d.sizes[static_cast<std::size_t>(d.dim)] !=
                                  d.base_samples * static_cast<std::int64_t>(d.factors.size() + 2))
      throw StoreError(impl_->path, "/designs/" + name + " is inconsistent (dims, sizes, dim, base_samples, factors)");
    check_design_rows(impl_->file, impl_->path, impl_->n_runs, impl_->columns, d);
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace ks::store
