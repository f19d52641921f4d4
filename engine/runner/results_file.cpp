// The results file a sweep writes: refusals, shards, free space, the history policy of a resume, and
// the file opened or created (runner/sweep_backend.hpp).
#include "runner/sweep_backend.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "runner/study_meta.hpp"

namespace ks {

namespace fs = std::filesystem;

std::string refuse_existing(const std::string& out, bool exists, const std::string& what, const RunRequest& r) {
  if (!exists || r.resume || r.overwrite) return "";
  return out + " " + what + "; use --resume to complete it or --overwrite to replace it";
}

namespace {
/// The bytes a new results file takes before any run: every /runs row is allocated at creation (8
/// bytes per number, 16 per string reference, 1 for the done flag), plus 1 MiB for the rest.
std::uint64_t skeleton_bytes(const StudySchema& schema, std::uint64_t runs) {
  std::uint64_t row = 1;
  for (const auto& c : schema.columns) row += c.type == CellType::str ? 16 : 8;
  return runs * row + (1u << 20);
}

}  // namespace

std::vector<std::string> find_shards(const std::string& output) {
  const fs::path p(output);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const std::string prefix = p.filename().string() + ".rank";
  std::vector<std::pair<long, std::string>> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() <= prefix.size() + 3 || name.rfind(prefix, 0) != 0 || !name.ends_with(".h5")) continue;
    const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - 3);
    if (digits.empty() || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    found.emplace_back(std::stol(digits), (p.parent_path() / name).string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (auto& [r, path] : found) out.push_back(std::move(path));
  return out;
}

void check_free_space(const std::string& out, const StudySchema& schema, std::uint64_t runs, int files) {
  const fs::path dir = fs::path(out).parent_path().empty() ? fs::path(".") : fs::path(out).parent_path();
  {  // a folder no file can be created in (read-only, no permission) is no free-space problem
    const std::string probe = (dir / ("." + fs::path(out).filename().string() + ".probe-" + std::to_string(::getpid()))).string();
    const int fd = ::open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0600);
    if (fd < 0 && errno != EEXIST)
      throw store::StoreError(out, "cannot create a file in directory '" + dir.string() + "': " + std::strerror(errno) +
                                       "; expected a folder this user can write to");
    if (fd >= 0) ::close(fd), ::unlink(probe.c_str());
  }
  std::error_code ec;
  const fs::space_info sp = fs::space(dir, ec);
  if (ec) return;  // unknown: the writer reports a full disk as it happens
  const std::uint64_t need = skeleton_bytes(schema, runs) * static_cast<std::uint64_t>(files);
  if (need > sp.available)
    throw store::StoreError(out, (files == 1 ? "the file needs " : "the file and its shards need ") +
                                     std::to_string(need) + " bytes for their " + std::to_string(runs) +
                                     " run rows each before any run, but " + dir.string() + " has " +
                                     std::to_string(sp.available) + " bytes free; expected more free space "
                                     "(or fewer runs)");
}

namespace {
/// Refuses (StoreError) to resume a file whose /runs columns are not the study's (the same study
/// text under a kinesweep whose tables differ): its rows could not be read as this schema's.
void require_same_columns(const std::string& out, const std::vector<ColumnSpec>& file, const StudySchema& schema) {
  for (std::size_t c = 0; c < std::max(file.size(), schema.columns.size()); ++c) {
    const ColumnSpec* f = c < file.size() ? &file[c] : nullptr;
    const ColumnSpec* s = c < schema.columns.size() ? &schema.columns[c] : nullptr;
    if (f && s && f->name == s->name && f->type == s->type) continue;
    throw store::StoreError(out, "column " + std::to_string(c) + " of /runs is " + (f ? "'" + f->name + "'" : "absent") +
                                     ", the study's schema has " + (s ? "'" + s->name + "'" : "none") +
                                     " (refusing to resume: rerun with --overwrite)");
  }
}
}  // namespace

HistoryPolicy resume_histories(const std::string& path, const std::string& recorded, const HistoryPolicy& asked,
                               bool adopt) {
  HistoryPolicy p = asked;
  if (adopt && HistoryPolicy::parse(recorded, p)) return p;
  if (!recorded.empty() && recorded != asked.str())
    throw store::StoreError(path, "its runs were written with histories = " + recorded + ", this run asks for " +
                                      asked.str() + " ([study] histories or --histories): resume with --histories " +
                                      recorded + " (refusing to resume: rerun with --overwrite to replace the file)");
  return asked;
}

std::string histories_argument(const RunRequest& request) {
  return request.histories_given ? " --histories " + request.options.histories.str() : "";
}

OpenedResults open_results(const Study& study, const StudySchema& schema, const std::string& out, bool resume,
                           const store::StoreOptions& so, const HistoryPolicy& histories, bool adopt_recorded) {
  OpenedResults r;
  r.histories = histories;
  if (resume && fs::exists(out)) {
    // a file of other columns is refused before the writer opens it (which writes to it); a file the
    // reader cannot open (one a journal must recover first) is checked once the writer has it
    std::optional<std::vector<ColumnSpec>> readable;
    try {
      readable = store::ResultsReader(out).columns();
    } catch (const std::exception&) {
    }
    if (readable) require_same_columns(out, *readable, schema);
    r.writer = std::move(store::ResultsWriter::open_for_resume(out, study.sha256, so).writer);
    r.histories = resume_histories(out, r.writer->recorded_histories(), histories, adopt_recorded);
    if (const std::string why = history_memory_problem(study, r.histories); !why.empty())
      throw std::runtime_error(why);
    require_same_columns(out, r.writer->columns(), schema);
    r.previous = previous_runs(*r.writer);
    return r;
  }
  if (const std::string why = history_memory_problem(study, histories); !why.empty()) throw std::runtime_error(why);
  if (!fs::path(out).parent_path().empty()) fs::create_directories(fs::path(out).parent_path());
  check_free_space(out, schema, study.run_count(), 1);
  r.writer = store::ResultsWriter::create(out, store_meta(study, histories), schema.columns,
                                         static_cast<std::int64_t>(study.run_count()), so);
  return r;
}

}  // namespace ks
