// ResultsWriter::open_for_resume (see store.hpp, FORMAT.md "Creation, overwrite, resume").
#include <sys/stat.h>

#include <cctype>
#include <cerrno>
#include <cstring>

#include "store/h5util.hpp"
#include "store/journal_vfd.hpp"
#include "store/store.hpp"
#include "store/writer_impl.hpp"

namespace ks::store {
using namespace detail;

ResultsWriter::Resumed ResultsWriter::open_for_resume(const std::string& path, const std::string& expected_sha256,
                                                      const StoreOptions& options) {
  QuietHdf5 quiet;
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) throw StoreError(path, std::string("cannot resume: ") + std::strerror(errno));
  auto impl = open_writer_impl(path, options);
  hid_t f = impl->file;
  if (read_str_attr(f, "format") != kFormatName)
    throw StoreError(path, "not a kinesweep results file (attribute format != kinesweep-results)");
  if (read_i64_attr(f, "format_version", -1) != kFormatVersion)
    throw StoreError(path, "unsupported format_version " + std::to_string(read_i64_attr(f, "format_version", -1)));
  auto lower = [](std::string s) {
    for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return s;
  };
  const std::string sha = read_str_attr(f, "study_sha256");
  if (lower(sha) != lower(expected_sha256))
    throw StoreError(path, "study sha256 mismatch: the file was written for study " + sha +
                               ", the study given now has " + expected_sha256 + " (refusing to resume)");
  impl->columns = read_run_columns(f, path, impl->n_runs);
  impl->open_objects();
  if (impl->n_runs < 0) impl->n_runs = H5Sget_simple_extent_npoints(Hid(H5Dget_space(impl->done_dset)));
  impl->done.assign(static_cast<std::size_t>(impl->n_runs), 0);
  if (impl->n_runs > 0)
    check(H5Dread(impl->done_dset, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, impl->done.data()), path,
          "read /runs/done");
  Resumed r;
  for (std::int64_t i = 0; i < impl->n_runs; ++i)
    if (impl->done[static_cast<std::size_t>(i)]) r.done.push_back(i);
  r.writer = std::unique_ptr<ResultsWriter>(new ResultsWriter(std::move(impl)));
  return r;
}

}  // namespace ks::store
