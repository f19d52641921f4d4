// Study diagnostics: FILE:LINE:COL: error: message, and StudyError listing them.
#include <string>
#include <vector>

#include "study/study.hpp"

namespace ks {

std::string StudyDiagnostic::str() const {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: " + message;
}

namespace {
std::string join_diagnostics(const std::vector<StudyDiagnostic>& d) {
  std::string s;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (i) s += '\n';
    s += d[i].str();
  }
  return s;
}
}  // namespace

StudyError::StudyError(std::vector<StudyDiagnostic> diagnostics)
    : std::runtime_error(join_diagnostics(diagnostics)), diagnostics_(std::move(diagnostics)) {}

}  // namespace ks
