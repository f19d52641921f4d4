#pragma once
// Words of a command line the program prints for the user to paste (e.g. the resume hint).
#include <string>

namespace ks {

/// `s` as one POSIX shell word: unchanged when it holds only characters no shell treats specially,
/// else in single quotes (an embedded ' written as '\'').
inline std::string shell_word(const std::string& s) {
  const std::string safe = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_./:=@%+,-";
  if (!s.empty() && s.find_first_not_of(safe) == std::string::npos) return s;
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// The command that runs this program again as the user typed it: argv[0] when it names a path
/// (absolute, or relative to the directory it was started from), else "kinesweep" (found on PATH).
inline std::string command_name(const std::string& argv0) {
  return argv0.find('/') == std::string::npos ? std::string("kinesweep") : shell_word(argv0);
}

/// The command line this process was started with, as shell words (set once by main; "" until then):
/// results files record it (root attribute command_line).
inline std::string& process_command_line() {
  static std::string line;
  return line;
}

}  // namespace ks
