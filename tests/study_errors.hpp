#pragma once
// Located study errors in the parser tests: the error of a text, and a check of its first diagnostic.
#include <gtest/gtest.h>

#include <string>

#include "study/study.hpp"

namespace ks::study_test {

/// Parse `text` (as "bad.toml") expecting a StudyError; returns it (fails the test when parsing succeeds).
inline StudyError error_of(const std::string& text, StudyOptions opt = {}) {
  try {
    parse_study(text, "bad.toml", opt);
  } catch (const StudyError& e) {
    return e;
  }
  ADD_FAILURE() << "no StudyError for:\n" << text;
  return StudyError({});
}

/// The first diagnostic is at bad.toml:line:col, its message contains `part` and "; expected ", and
/// the error's text starts with "bad.toml:LINE:COL: error: ".
inline void expect_error_at(const std::string& text, int line, int col, const std::string& part,
                            StudyOptions opt = {}) {
  const StudyError e = error_of(text, opt);
  ASSERT_FALSE(e.diagnostics().empty());
  const auto& d = e.diagnostics().front();
  EXPECT_EQ(d.file, "bad.toml");
  EXPECT_EQ(d.line, line) << e.what();
  EXPECT_EQ(d.column, col) << e.what();
  EXPECT_NE(d.message.find(part), std::string::npos) << e.what();
  EXPECT_NE(d.message.find("; expected "), std::string::npos) << e.what();
  const std::string prefix = "bad.toml:" + std::to_string(line) + ":" + std::to_string(col) + ": error: ";
  EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << e.what();
}

}  // namespace ks::study_test
