#pragma once
// Internal to engine/study (not included from outside it): the study parser. One Parser reads one
// study text; its parts live in the files named for their jobs:
//   study_tables.cpp     [study], [robot], [task]
//   axes.cpp             parameter values and the [block.axes] forms (values, range, linspace, random, lhs)
//   blocks.cpp           [[block]] tables: fixed parameters, lhs and zip groups, axes a run would ignore
//   optimize_tables.cpp  [[optimize]] tables and their stages
//   parse.cpp            Parser::run, parse_study, load_study
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "study/toml_access.hpp"

namespace ks::study_parse {

/// At most this many samples per trajectory run (the seed takes 2001): each thread keeps the sampled
/// path, and a full history holds 16 doubles per sample.
constexpr double kMaxSamples = 1e7;

/// One axis of [block.axes] as parsed, before the block's LHS group is drawn.
struct AxisDraft {
  Axis axis;
  Pos pos;                                   // the axis key
  bool lhs = false;
  std::pair<double, double> lhs_range{0, 0};  // LHS axes: [from, to) in file units
};

/// The metrics an [[optimize]] objective may name for runs of kind `k`.
std::vector<std::string> objective_names(BlockKind k);

class Parser : public ParserCore {
 public:
  /// `text` must outlive the parser.
  Parser(std::string file, std::string_view text, StudyOptions options)
      : ParserCore(std::move(file), text), text_(text), options_(options) {}

  Study run();

 private:
  // study_tables.cpp
  void parse_study_table(const toml::table& root, Study& s);
  void parse_robot(const toml::table& root, Study& s);
  void parse_task(const toml::table& root, Study& s);

  // blocks.cpp
  void parse_blocks(const toml::table& root, Study& s);
  /// One [[block]] table, or with optimize = true the block part of an [[optimize]] table. `names`
  /// holds the names seen so far (and where).
  std::optional<Block> parse_block(const toml::table& b, std::size_t index, const Study& s,
                                   std::map<std::string, Pos>& names, bool optimize = false);

  // optimize_tables.cpp: [[optimize]] tables, a block (parse_block with optimize = true) + the
  // optimisation keys.
  void parse_optimizations(const toml::table& root, Study& s);
  std::optional<opt::StageOptions> parse_stage(const toml::node& n, bool global, OptimizeBlock& ob);

  // axes.cpp
  /// One axis of [block.axes] (its values in stored units; LHS axes get their values later).
  std::optional<AxisDraft> parse_axis(const ParamInfo& info, const toml::key& key, const toml::node& node,
                                      const toml::node* lhs_node);
  /// A parameter value from a node: type + choices + unit conversion + domain. nullopt on error.
  std::optional<Cell> param_value(const ParamInfo& info, const toml::node& n);
  /// Check a stored numeric value's domain (expects file units for messages). Empty when fine.
  std::string domain_problem(const ParamInfo& info, double file_value);
  /// A count >= 1 and at most max_runs, and from <= to (random and linspace axes); false after reporting.
  bool count_and_interval_ok(const std::string& what, std::int64_t count, const toml::node& count_node, double from,
                             double to, const toml::node& at);

  std::string_view text_;
  StudyOptions options_;
  std::uint64_t max_runs_ = 0;
  double path_duration_ = 2.0;  // [s], the task's; bounds the samples a dt asks for
};

}  // namespace ks::study_parse
