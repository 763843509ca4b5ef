#include "io/file_scan.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <type_traits>

#include <sys/stat.h>

namespace plume::io::detail {

std::string read_file_bytes(const std::string &path) {
  // Only a regular file has an end to read to: a device such as /dev/zero would be read until memory
  // runs out, and a pipe would wait for a writer (before opening it, which waits too).
  struct stat status;
  if (stat(path.c_str(), &status) == 0 && !S_ISREG(status.st_mode))
    throw InputError(FileLoc{path}, "cannot read file: not a regular file");
  std::unique_ptr<FILE, int (*)(FILE *)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) throw InputError(FileLoc{path}, std::string("cannot open file: ") + std::strerror(errno));
  std::string bytes;
  char buffer[1 << 16];
  size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof(buffer), file.get())) > 0) bytes.append(buffer, got);
  if (std::ferror(file.get())) throw InputError(FileLoc{path}, std::string("cannot read file: ") + std::strerror(errno));
  return bytes;
}

std::string extension_of(const std::string &path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

std::string quoted(std::string_view token, size_t max_shown, bool keep_utf8) {
  size_t end = std::min(token.size(), max_shown);
  if (keep_utf8)  // back to the start of a UTF-8 character
    while (end < token.size() && end > 0 && ((unsigned char)token[end] & 0xc0) == 0x80) --end;
  std::string s = "\"";
  for (size_t i = 0; i < end; ++i) {
    const unsigned char c = (unsigned char)token[i];
    if ((c >= 32 && c < 127) || (keep_utf8 && c >= 128)) {
      s += char(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      s += hex;
    }
  }
  if (end < token.size()) s += "...";
  return s + "\"";
}

std::string number_text(double value) {
  char buffer[32];
  // A float's value (read from a float field) is shown as the float it was written as: 7e+31, not
  // the double 7.000000135555409e+31.
  const auto result = fits_float(value) && double(float(value)) == value
                          ? std::to_chars(buffer, buffer + sizeof(buffer), float(value))
                          : std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

// Halfway between the largest float and 2^128: from there on, a double rounds to infinity.
constexpr double kFloatOverflow = 0x1.ffffffp127;

bool fits_float(double value) { return std::abs(value) < kFloatOverflow; }

float to_float(double value) {
  const double largest = double(std::numeric_limits<float>::max());
  return float(std::clamp(value, -largest, largest));
}

std::string float_range_message(double value) {
  if (!std::isfinite(value)) return "expected a finite number, got " + number_text(value);
  std::string largest;
  append_number(largest, std::numeric_limits<float>::max());
  return "expected a number within float range (magnitude at most " + largest + "), got " + number_text(value);
}

bool valid_width(double value) { return value >= 0.0 && fits_float(value); }

std::string width_message(double value) {
  if (std::isfinite(value) && value >= 0.0) return "expected a finite number >= 0 within float range, got " + number_text(value);
  return "expected a finite number >= 0, got " + number_text(value);
}

namespace {

template <class Real>
NumberStatus parse_real(std::string_view token, Real &r_value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto result = std::from_chars(token.data(), token.data() + token.size(), r_value);
  if (token.empty() || (result.ec != std::errc() && result.ec != std::errc::result_out_of_range) ||
      result.ptr != token.data() + token.size())
    return NumberStatus::NotANumber;
  if (result.ec == std::errc::result_out_of_range) {
    // Too large, or too small: the C library tells which (the syntax is the same as from_chars').
    const std::string text(token);
    const Real value = std::is_same_v<Real, float> ? Real(std::strtof(text.c_str(), nullptr)) : Real(std::strtod(text.c_str(), nullptr));
    if (!(std::abs(value) < Real(1))) return NumberStatus::NotFinite;
    r_value = value;
  }
  return std::isfinite(r_value) ? NumberStatus::Ok : NumberStatus::NotFinite;
}

}  // namespace

NumberStatus parse_float(std::string_view token, float &r_value) { return parse_real(token, r_value); }
NumberStatus parse_double(std::string_view token, double &r_value) { return parse_real(token, r_value); }

NumberStatus parse_int(std::string_view token, long long &r_value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto result = std::from_chars(token.data(), token.data() + token.size(), r_value);
  if (token.empty() || result.ec != std::errc() || result.ptr != token.data() + token.size()) return NumberStatus::NotANumber;
  return NumberStatus::Ok;
}

bool LineCursor::next() {
  if (next_start_ >= text_.size()) return false;
  const size_t newline = text_.find('\n', next_start_);
  const size_t end = newline == std::string_view::npos ? text_.size() : newline;
  line_ = text_.substr(next_start_, end - next_start_);
  if (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);
  next_start_ = newline == std::string_view::npos ? text_.size() : newline + 1;
  ++line_number_;
  return true;
}

size_t LineCursor::lines_left() const {
  if (next_start_ >= text_.size()) return 0;
  const std::string_view rest = text_.substr(next_start_);
  const size_t newlines = size_t(std::count(rest.begin(), rest.end(), '\n'));
  return newlines + (rest.back() == '\n' ? 0 : 1);
}

FileLoc LineCursor::loc(std::string_view at) const {
  FileLoc loc{path_, line_number_};
  if (!at.empty() && at.data() >= line_.data() && at.data() <= line_.data() + line_.size())
    loc.column = int(at.data() - line_.data()) + 1;
  return loc;
}

void LineCursor::fail(std::string_view at, const std::string &message) const { throw InputError(loc(at), message); }

int LineCursor::to_obj_index(std::string_view token, std::string_view number, size_t count, std::string_view what,
                             std::string_view plural) const {
  const long long index = to_int(number, std::string(what) + " index");
  const long long resolved = index < 0 ? (long long)count + index : index - 1;
  if (index == 0 || resolved < 0 || resolved >= (long long)count)
    fail(token, std::string(what) + " index " + std::to_string(index) + " out of range, expected 1.." +
                    std::to_string(count) + " or -" + std::to_string(count) + "..-1 (" + std::string(plural) +
                    " read so far: " + std::to_string(count) + ")");
  return int(resolved);
}

std::string_view LineCursor::take_token(std::string_view &rest) {
  size_t begin = 0;
  while (begin < rest.size() && (rest[begin] == ' ' || rest[begin] == '\t')) ++begin;
  size_t end = begin;
  while (end < rest.size() && rest[end] != ' ' && rest[end] != '\t') ++end;
  const std::string_view token = rest.substr(begin, end - begin);
  rest.remove_prefix(end);
  return token;
}

Eigen::Vector3f LineCursor::take_vec3(std::string_view &rest, std::string_view keyword) const {
  const std::string name(keyword);
  Eigen::Vector3f p;
  p.x() = to_float(take_token(rest), name + ": x");
  p.y() = to_float(take_token(rest), name + ": y");
  p.z() = to_float(take_token(rest), name + ": z");
  return p;
}

float LineCursor::to_float(std::string_view token, std::string_view what) const {
  if (token.empty()) fail(line_.substr(line_.size()), std::string(what) + ": expected a number, got the end of the line");
  float value = 0.0f;
  const NumberStatus status = parse_float(token, value);
  if (status == NumberStatus::NotANumber) fail(token, std::string(what) + ": expected a number, got " + quoted(token));
  if (status == NumberStatus::NotFinite) fail(token, std::string(what) + ": expected a finite number, got " + quoted(token));
  return value;
}

long long LineCursor::to_int(std::string_view token, std::string_view what) const {
  if (token.empty()) fail(line_.substr(line_.size()), std::string(what) + ": expected an integer, got the end of the line");
  long long value = 0;
  if (parse_int(token, value) != NumberStatus::Ok) fail(token, std::string(what) + ": expected an integer, got " + quoted(token));
  return value;
}

void ByteCursor::require(size_t offset, uint64_t count, uint64_t item_bytes, std::string_view what) const {
  const uint64_t available = offset <= bytes_.size() ? bytes_.size() - offset : 0;
  // Divide rather than multiply so that a count near 2^64 cannot overflow.
  if (item_bytes != 0 && count > available / item_bytes)
    fail(offset, std::string(what) + ": expected " + std::to_string(count) + " x " + std::to_string(item_bytes) +
                     " bytes, file ends after " + std::to_string(available));
}


}  // namespace plume::io::detail
