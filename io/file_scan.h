// Helpers shared by the readers and writers in io/: whole-file loading, a line cursor and a byte
// cursor that turn every problem into an InputError at `file:line:col` or `file@byte N`, and
// shortest round-trip number formatting.
#pragma once

#include <Eigen/Core>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>

#include "groom/error.h"

namespace plume::io::detail {

static_assert(std::endian::native == std::endian::little, "the binary readers assume a little-endian host");

/// The whole file as bytes. Throws InputError naming the file when it is missing, unreadable or not a
/// regular file (a device or a pipe).
std::string read_file_bytes(const std::string &path);

/// Lower-case extension with its dot (".usda"), or "" when the name has none (as std::filesystem
/// reads it: a name that only starts with a dot, ".hair", has none). Every part of Plume that picks
/// a format from a file name uses this one.
std::string extension_of(const std::string &path);

/// Quotes a token for a message: escapes as \xNN the bytes that are not printable ASCII (with
/// `keep_utf8`, only control characters: UTF-8 text stays readable), and cuts it after `max_shown`
/// bytes (before a whole UTF-8 character) with "..." inside the quotes.
std::string quoted(std::string_view token, size_t max_shown = 40, bool keep_utf8 = false);

/// Shortest text of a number ("1e+300", "0.5", "nan", "-inf"); a value that is exactly a float, as
/// its shortest text as a float ("7e+31", not "7.000000135555409e+31").
std::string number_text(double value);

/// Whether a number read as a double becomes a finite float: false for NaN, infinities and
/// magnitudes that round to infinity (1e300). A reader checks before it narrows.
bool fits_float(double value);
/// The float nearest `value`, which must fit_float() (the conversion beyond the largest float is
/// undefined in C++ even where it rounds down to it).
float to_float(double value);
/// "expected a finite number, got nan" or "expected a number within float range (magnitude at most
/// 3.4028235e+38), got 1e+300", for a value that fails fits_float().
std::string float_range_message(double value);
/// Whether a strand width is a number >= 0 that fits a float.
bool valid_width(double value);
/// "expected a finite number >= 0, got -1" for a value that fails valid_width().
std::string width_message(double value);

enum class NumberStatus { Ok, NotANumber, NotFinite };
/// Parses a whole token as a float (a leading '+' is allowed); NotFinite for nan, inf or overflow.
/// A number too small for a float reads as the nearest one (0 or a subnormal), as strtof gives it.
NumberStatus parse_float(std::string_view token, float &r_value);
/// parse_float() for a double.
NumberStatus parse_double(std::string_view token, double &r_value);
/// Parses a whole token as an integer (a leading '+' is allowed).
NumberStatus parse_int(std::string_view token, long long &r_value);

/// Walks a text buffer line by line; line() excludes the newline and a trailing '\r'.
class LineCursor {
 public:
  LineCursor(std::string_view text, const std::string &path) : text_(text), path_(path) {}

  /// Moves to the next line; false at the end of the text.
  bool next();
  std::string_view line() const { return line_; }
  int line_number() const { return line_number_; }
  /// Offset of the first byte after the current line (where binary data after a text header starts).
  size_t end_offset() const { return next_start_; }
  const std::string &path() const { return path_; }
  /// Lines left after the current one (counting a last line without newline).
  size_t lines_left() const;

  /// Location of `at` (a view into line()) or of the line itself.
  FileLoc loc(std::string_view at = {}) const;
  [[noreturn]] void fail(std::string_view at, const std::string &message) const;
  [[noreturn]] void fail(const std::string &message) const { fail({}, message); }

  /// Next whitespace-separated token of `rest`, consuming it; empty when there is none.
  static std::string_view take_token(std::string_view &rest);
  /// Parses a finite float; `what` names the value in the message.
  float to_float(std::string_view token, std::string_view what) const;
  /// Takes three finite floats from `rest` (an OBJ `v x y z` body); messages say "<keyword>: x" etc.
  Eigen::Vector3f take_vec3(std::string_view &rest, std::string_view keyword) const;
  /// Parses an integer.
  long long to_int(std::string_view token, std::string_view what) const;
  /// Parses an OBJ index from `number` (part of `token`): 1-based, or negative counting back from the
  /// last of the `count` elements read so far. Returns it 0-based; fails at `token` when it is out of
  /// range. `what` names the index's kind ("f: vertex"), `plural` the elements ("vertices").
  int to_obj_index(std::string_view token, std::string_view number, size_t count, std::string_view what,
                   std::string_view plural) const;

 private:
  std::string_view text_;
  std::string path_;
  std::string_view line_;
  size_t next_start_ = 0;
  int line_number_ = 0;
};

/// Reads little-endian values from a byte buffer, failing with the byte offset.
class ByteCursor {
 public:
  ByteCursor(std::string_view bytes, const std::string &path) : bytes_(bytes), path_(path) {}

  size_t size() const { return bytes_.size(); }
  const std::string &path() const { return path_; }
  FileLoc loc(size_t offset) const { return FileLoc{path_, 0, 0, (long long)offset}; }
  [[noreturn]] void fail(size_t offset, const std::string &message) const { throw InputError(loc(offset), message); }

  /// Throws "`what`: expected `count` x `item_bytes` bytes, file ends after R" unless the bytes fit.
  void require(size_t offset, uint64_t count, uint64_t item_bytes, std::string_view what) const;

  template <class T>
  T get(size_t offset) const {
    T value;
    std::memcpy(&value, bytes_.data() + offset, sizeof(T));
    return value;
  }

 private:
  std::string_view bytes_;
  std::string path_;
};

/// Shortest decimal form that reads back to exactly the same float (std::to_chars).
inline void append_number(std::string &out, float value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}
inline void append_number(std::string &out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}
inline void append_number(std::string &out, long long value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}
inline void append_number(std::string &out, unsigned long long value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

/// `text` as a USD string literal: in double quotes, with quotes, backslashes and newlines escaped.
inline void append_string_literal(std::string &out, std::string_view text) {
  out += '"';
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  out += '"';
}

/// A `.usda` layer's header up to its closing parenthesis: doc (when `comment` is not empty),
/// defaultPrim "Groom", metersPerUnit, upAxis and, with a time code, the layer's time range (that one
/// frame) and rate.
inline void append_layer_header(std::string &out, std::string_view comment, double meters_per_unit,
                                std::string_view up_axis, const std::optional<double> &time_code, double fps) {
  out += "#usda 1.0\n(\n";
  if (!comment.empty()) {
    out += "    doc = ";
    append_string_literal(out, comment);
    out += '\n';
  }
  out += "    defaultPrim = \"Groom\"\n    metersPerUnit = ";
  append_number(out, meters_per_unit);
  out += "\n    upAxis = ";
  append_string_literal(out, up_axis);
  out += '\n';
  if (time_code) {
    for (const char *key : {"startTimeCode", "endTimeCode"}) {
      out += std::string("    ") + key + " = ";
      append_number(out, *time_code);
      out += '\n';
    }
    out += "    timeCodesPerSecond = ";
    append_number(out, fps);
    out += '\n';
  }
  out += ")\n\n";
}

/// `n` floats as a USD tuple: "(x, y, z)".
inline void append_tuple(std::string &out, const float *values, int n) {
  out += '(';
  for (int k = 0; k < n; ++k) {
    if (k > 0) out += ", ";
    append_number(out, values[k]);
  }
  out += ')';
}

}  // namespace plume::io::detail
