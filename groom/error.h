// Typed errors thrown by Plume's libraries. Library code never prints or exits; app/ maps
// InputError to exit code 2 and everything else to exit code 1.
#pragma once

#include <stdexcept>
#include <string>

namespace plume {

/// Where a parsed value came from. line/column are 1-based; 0 means "not applicable"
/// (for binary files, byte_offset is used instead and line is 0).
struct FileLoc {
  std::string file;
  int line = 0;
  int column = 0;
  long long byte_offset = -1;

  /// "file:line:col", "file:line", "file@byte N" or "file", whichever is known.
  std::string str() const;
  /// Whether anything of the place is known (a default FileLoc knows nothing).
  bool known() const { return !file.empty() || line > 0 || byte_offset >= 0; }
};

/// Bad input: a malformed file, a missing file, a NaN, an absurd count, a degenerate mesh.
/// what() is the full message "file:line:col: key.path: expected X, got Y"; the message alone when
/// the place is not known (a default FileLoc, as callers pass for input given in code).
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string &message) : std::runtime_error(message) {}
  InputError(const FileLoc &loc, const std::string &message)
      : std::runtime_error(loc.known() ? loc.str() + ": " + message : message), loc_(loc) {}
  const FileLoc &loc() const { return loc_; }

 private:
  FileLoc loc_;
};

/// A broken invariant inside Plume (a bug, not bad input).
class InternalError : public std::logic_error {
 public:
  explicit InternalError(const std::string &message) : std::logic_error(message) {}
};

}  // namespace plume
