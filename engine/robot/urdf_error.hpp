#pragma once
// The error of a robot file that cannot be read or does not describe a chain the engine can simulate,
// with its location: thrown by the URDF reader (robot/urdf.hpp) and its strict checker
// (robot/urdf_check.hpp).
#include <stdexcept>
#include <string>

namespace ks {

/// A URDF file that cannot be read or does not describe a chain the engine can simulate.
struct UrdfError : std::runtime_error {
  std::string file;     ///< the file (or the name given to parse_urdf)
  int line = 0;         ///< 1-based line of the element at fault; 0 when unknown
  std::string message;  ///< what is wrong, without the location
  int column = 0;       ///< 1-based column (characters) on that line; 0 when unknown
  /// what(): "file:line:column: message", the line and column when known.
  UrdfError(std::string file_, int line_, std::string message_, int column_ = 0)
      : std::runtime_error(file_ + (line_ > 0 ? ":" + std::to_string(line_) : std::string()) +
                           (line_ > 0 && column_ > 0 ? ":" + std::to_string(column_) : std::string()) + ": " +
                           message_),
        file(std::move(file_)),
        line(line_),
        message(std::move(message_)),
        column(column_) {}
};

}  // namespace ks
