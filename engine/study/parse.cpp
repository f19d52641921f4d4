// Study-file parser: TOML (toml++) -> validated Study. Collects every error it can, each located; the
// parts of the Parser are listed in study/parser.hpp.
#include <algorithm>
#include <fstream>
#include <limits>
#include <sstream>

#include "study/parser.hpp"
#include "study/sha256.hpp"

namespace ks {

std::string HistoryPolicy::str() const {
  switch (mode) {
    case Mode::full: return "full";
    case Mode::none: return "none";
    case Mode::every: return "every=" + std::to_string(stride);
  }
  return "?";
}

bool HistoryPolicy::parse(const std::string& s, HistoryPolicy& p) {
  if (s == "full" || s == "none") {
    p = s == "full" ? HistoryPolicy{Mode::full, 1} : HistoryPolicy{Mode::none, 0};
    return true;
  }
  if (s.rfind("every=", 0) != 0 || s.size() == 6 || s.size() > 15) return false;
  long n = 0;
  for (std::size_t i = 6; i < s.size(); ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
    n = n * 10 + (s[i] - '0');
  }
  if (n < 1 || n > std::numeric_limits<int>::max()) return false;
  p = {Mode::every, static_cast<int>(n)};
  return true;
}

std::size_t Study::block_index(std::string_view n) const {
  for (std::size_t i = 0; i < blocks.size(); ++i)
    if (blocks[i].name() == n) return i;
  return Block::npos;
}

Study study_parse::Parser::run() {
  const std::string_view text = text_;
  Study s;
  s.file = file_;
  s.text = std::string(text);
  s.sha256 = sha256_hex(text);
  if (const auto h = toml_hazard(text)) {  // inputs toml++ 3.3 mishandles: refused before it parses
    error(Pos{h->line, h->column, 1}, "TOML syntax: " + h->message);
    throw StudyError(diags_);
  }
  toml::table root;
  try {
    root = toml::parse(text, file_);
  } catch (const toml::parse_error& e) {
    error(e.source(), "TOML syntax: " + std::string(e.description()) + "; expected valid TOML (https://toml.io)");
    throw StudyError(diags_);
  }
  const auto fail = [this] {
    std::stable_sort(diags_.begin(), diags_.end(), [](const StudyDiagnostic& a, const StudyDiagnostic& b) {
      return std::pair(a.line, a.column) < std::pair(b.line, b.column);
    });
    throw StudyError(diags_);
  };
  check_keys(root, {"study", "robot", "task", "world", "block", "optimize"}, "the top level");
  parse_study_table(root, s);
  const std::size_t before_robot = diags_.size();
  parse_robot(root, s);
  // the task's points, the blocks' parameters and the reach follow from the robot: checked against
  // a robot in error (another robot in its place) they would only add false errors
  if (diags_.size() > before_robot) fail();
  place_robot_in_plane(s);
  parse_task(root, s);
  parse_world(root, s);
  s.arm_chain = s.robot_chain();
  if (!s.robot_text.empty()) s.sha256 = sha256_hex(std::string(text) + std::string(1, '\0') + s.robot_text);  // the robot is part of the study
  if (root.get("block") || !root.get("optimize")) parse_blocks(root, s);
  parse_optimizations(root, s);
  // the path matters to trajectory runs only (an IK study's chain need not reach the default square)
  const auto trajectory = [](const Block& b) { return b.kind() == BlockKind::trajectory; };
  if (std::any_of(s.blocks.begin(), s.blocks.end(), trajectory) ||
      std::any_of(s.optimizations.begin(), s.optimizations.end(),
                  [&](const OptimizeBlock& o) { return trajectory(o.block()); })) {
    check_task_fits_robot(root.get("task") ? root.get("task")->as_table() : nullptr, s);
    check_gravity_given(s);
  }
  if (!diags_.empty()) fail();
  return s;
}

Study parse_study(std::string_view text, std::string_view file, const StudyOptions& options) {
  return study_parse::Parser(std::string(file), text, options).run();
}

Study load_study(const std::filesystem::path& file, const StudyOptions& options) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) {
    StudyDiagnostic d;
    d.file = file.string();
    d.line = d.column = 1;
    std::vector<std::string> studies;  // the study files in it, as suggestions
    for (const auto& e : std::filesystem::directory_iterator(file, ec))
      if (e.path().extension() == ".toml") studies.push_back(e.path().string());
    std::sort(studies.begin(), studies.end());
    d.message = "is a directory; expected a study file (TOML)";
    for (std::size_t i = 0; i < studies.size() && i < 3; ++i) d.message += (i ? ", " : ", e.g. ") + studies[i];
    if (studies.size() > 3) d.message += ", ...";
    throw StudyError({d});
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    StudyDiagnostic d;  // no source line: the headline alone
    d.file = file.string();
    d.line = d.column = 1;
    d.message = "cannot read the study file; expected a readable TOML file";
    throw StudyError({d});
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_study(ss.str(), file.string(), options);
}

}  // namespace ks
