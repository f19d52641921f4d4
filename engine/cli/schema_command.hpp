#pragma once
// `kinesweep schema [--format markdown|json]`: the run parameters and metrics of every kind, as the
// tables in engine/schema declare them (name, type, units, domain, default, effect rule, meaning).
// engine/store/FORMAT.md's column list is this command's markdown output (checked by a test).
#include <iosfwd>
#include <string>

namespace CLI {
class App;
}

namespace ks::cli {

struct SchemaArgs {
  std::string format = "markdown";
};

SchemaArgs& add_schema_command(CLI::App& app);
int schema_command(const SchemaArgs& args);
/// The markdown column list (what FORMAT.md holds between its generated-section markers).
void print_schema_markdown(std::ostream& os);
void print_schema_json(std::ostream& os);

}  // namespace ks::cli
