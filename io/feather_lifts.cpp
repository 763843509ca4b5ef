#include "io/feather_lifts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <unordered_set>

#include "groom/error.h"
#include "io/atomic_file.h"
#include "io/file_scan.h"

namespace plume::io {

namespace {

constexpr const char *kHeader = "plume feather lifts 4";
constexpr const char *kHeaderVersion3 = "plume feather lifts 3";
constexpr const char *kHeaderVersion2 = "plume feather lifts 2";
constexpr const char *kHeaderVersion1 = "plume feather lifts 1";
constexpr float kPi = 3.14159265358979f;

/// The next line that is not blank or a comment; false at the end.
bool next_content(detail::LineCursor &cursor, std::string_view &r_rest) {
  while (cursor.next()) {
    r_rest = cursor.line();
    if (const size_t hash = r_rest.find('#'); hash != std::string_view::npos) r_rest = r_rest.substr(0, hash);
    std::string_view probe = r_rest;
    if (!detail::LineCursor::take_token(probe).empty()) return true;
  }
  return false;
}

/// `keyword <integer>` on the next content line.
long long keyword_value(detail::LineCursor &cursor, std::string_view keyword) {
  std::string_view rest;
  if (!next_content(cursor, rest))
    throw InputError(FileLoc{cursor.path(), cursor.line_number()},
                     std::string(keyword) + ": expected \"" + std::string(keyword) + " N\", got the end of the file");
  const std::string_view token = detail::LineCursor::take_token(rest);
  if (token != keyword)
    cursor.fail(token, std::string(keyword) + ": expected \"" + std::string(keyword) + " N\", got " + detail::quoted(token));
  const long long value = cursor.to_int(detail::LineCursor::take_token(rest), keyword);
  if (const std::string_view extra = detail::LineCursor::take_token(rest); !extra.empty())
    cursor.fail(extra, std::string(keyword) + ": expected one number, got more: " + detail::quoted(extra));
  return value;
}

}  // namespace

std::string feather_lifts_pattern(const std::string &guide_cache_pattern) {
  const std::filesystem::path path(guide_cache_pattern);
  return (path.parent_path() / path.stem()).string() + ".lifts";
}

void write_feather_lifts(const std::string &path, const FeatherLifts &lifts) {
  std::string text = std::string(kHeader) + "\nframe " + std::to_string(lifts.frame) + "\nfeathers " +
                     std::to_string(lifts.ids.size()) + "\nlayers " + (lifts.layered ? "1" : "0") +
                     (lifts.layered ? "\n# id lift scale layer_turn layer_scale layer_yaw layer_bend layer_bend_start "
                                      "(radians; sizes, 1 when not shrunk; yaw 0 unless turned aside, bend 0 "
                                      "unless bent; bend start, a fraction of the shaft)\n"
                                    : "\n# id lift scale (radians; size, 1 when not shrunk)\n");
  char line[224];
  for (size_t i = 0; i < lifts.ids.size(); ++i) {
    if (lifts.layered)
      std::snprintf(line, sizeof line, "%llu %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", (unsigned long long)lifts.ids[i],
                    double(lifts.lifts[i]), double(lifts.scales[i]), double(lifts.layer_turns[i]),
                    double(lifts.layer_scales[i]), lifts.layer_yaws.empty() ? 0.0 : double(lifts.layer_yaws[i]),
                    lifts.layer_bends.empty() ? 0.0 : double(lifts.layer_bends[i]),
                    lifts.layer_bend_starts.empty() ? 0.0 : double(lifts.layer_bend_starts[i]));
    else
      std::snprintf(line, sizeof line, "%llu %.9g %.9g\n", (unsigned long long)lifts.ids[i], double(lifts.lifts[i]),
                    double(lifts.scales[i]));
    text += line;
  }
  AtomicFile file(path);
  file.write(text);
  file.commit();
}

FeatherLifts read_feather_lifts(const std::string &path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw InputError(FileLoc{path}, std::filesystem::exists(path, error)
                                        ? "feather lifts: not a file"
                                        : "feather lifts: the file does not exist (plume simulate writes one "
                                          "beside every guide cache frame of a feather groom)");
  const std::string text = detail::read_file_bytes(path);
  detail::LineCursor cursor(text, path);
  std::string_view rest;
  if (!next_content(cursor, rest))
    throw InputError(FileLoc{path}, "feather lifts: expected \"" + std::string(kHeader) + "\", got an empty file");
  while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\t' || rest.back() == '\r')) rest.remove_suffix(1);
  if (rest != kHeader && rest != kHeaderVersion3 && rest != kHeaderVersion2 && rest != kHeaderVersion1)
    cursor.fail("header: expected \"" + std::string(kHeader) + "\" (or version 3, 2 or 1), got " +
                detail::quoted(rest));
  const bool version1 = rest == kHeaderVersion1, version2 = rest == kHeaderVersion2,
             version3 = rest == kHeaderVersion3;
  FeatherLifts lifts;
  const long long frame = keyword_value(cursor, "frame");
  if (frame < -1000000000LL || frame > 1000000000LL) cursor.fail("frame: expected a frame number, got " + std::to_string(frame));
  lifts.frame = int(frame);
  const long long count = keyword_value(cursor, "feathers");
  if (count < 0 || count > 100000000LL)
    cursor.fail("feathers: expected a count in 0..100000000, got " + std::to_string(count));
  if (!version1) {
    const long long layers = keyword_value(cursor, "layers");
    if (layers != 0 && layers != 1) cursor.fail("layers: expected 0 or 1, got " + std::to_string(layers));
    lifts.layered = layers == 1;
  }
  const bool yawed = lifts.layered && !version2;
  const bool bent = yawed && !version3;
  const int columns = lifts.layered ? (bent ? 8 : yawed ? 6 : 5) : 3;
  // No more lines than the text can hold (a line takes at least 6 bytes): a wrong count allocates nothing.
  const size_t expected = std::min(size_t(count), text.size() / 6);
  lifts.ids.reserve(expected);
  lifts.lifts.reserve(expected);
  lifts.scales.reserve(expected);
  if (lifts.layered) {
    lifts.layer_turns.reserve(expected);
    lifts.layer_scales.reserve(expected);
    if (yawed) lifts.layer_yaws.reserve(expected);
    if (bent) {
      lifts.layer_bends.reserve(expected);
      lifts.layer_bend_starts.reserve(expected);
    }
  }
  std::unordered_set<uint64_t> seen;
  while (next_content(cursor, rest)) {
    const std::string what = "feather " + std::to_string(lifts.ids.size());
    if ((long long)lifts.ids.size() == count)
      cursor.fail(what + ": expected " + std::to_string(count) + " feathers (the count on the line \"feathers\"), "
                                                                  "got more");
    const std::string_view id_token = detail::LineCursor::take_token(rest);
    const long long id = cursor.to_int(id_token, what + ": id");
    if (id < 0) cursor.fail(id_token, what + ": id: expected a feather id (>= 0), got " + std::to_string(id));
    if (!seen.insert(uint64_t(id)).second) cursor.fail(id_token, what + ": id " + std::to_string(id) + " repeated");
    const std::string_view lift_token = detail::LineCursor::take_token(rest);
    const float lift = cursor.to_float(lift_token, what + ": lift");
    if (!(lift >= 0.0f && lift <= kPi + 1e-5f))
      cursor.fail(lift_token, what + ": lift: expected radians in [0, pi], got " + detail::quoted(lift_token));
    const std::string_view scale_token = detail::LineCursor::take_token(rest);
    const float scale = cursor.to_float(scale_token, what + ": scale");
    if (!(scale >= 0.0f && scale <= 1.0f))
      cursor.fail(scale_token, what + ": scale: expected a size in [0, 1], got " + detail::quoted(scale_token));
    if (lifts.layered) {
      const std::string_view turn_token = detail::LineCursor::take_token(rest);
      const float turn = cursor.to_float(turn_token, what + ": layer_turn");
      if (!(turn >= 0.0f && turn <= kPi + 1e-5f))
        cursor.fail(turn_token, what + ": layer_turn: expected radians in [0, pi], got " + detail::quoted(turn_token));
      const std::string_view size_token = detail::LineCursor::take_token(rest);
      const float size = cursor.to_float(size_token, what + ": layer_scale");
      if (!(size >= 0.0f && size <= 1.0f))
        cursor.fail(size_token, what + ": layer_scale: expected a size in [0, 1], got " + detail::quoted(size_token));
      lifts.layer_turns.push_back(turn);
      lifts.layer_scales.push_back(size);
    }
    if (yawed) {
      const std::string_view yaw_token = detail::LineCursor::take_token(rest);
      const float yaw = cursor.to_float(yaw_token, what + ": layer_yaw");
      if (!(yaw >= -kPi - 1e-5f && yaw <= kPi + 1e-5f))
        cursor.fail(yaw_token, what + ": layer_yaw: expected radians in [-pi, pi], got " + detail::quoted(yaw_token));
      lifts.layer_yaws.push_back(yaw);
    }
    if (bent) {
      const std::string_view bend_token = detail::LineCursor::take_token(rest);
      const float bend = cursor.to_float(bend_token, what + ": layer_bend");
      if (!(bend >= -kPi - 1e-5f && bend <= kPi + 1e-5f))
        cursor.fail(bend_token, what + ": layer_bend: expected radians in [-pi, pi], got " + detail::quoted(bend_token));
      const std::string_view start_token = detail::LineCursor::take_token(rest);
      const float start = cursor.to_float(start_token, what + ": layer_bend_start");
      if (!(start >= 0.0f && start <= 1.0f))
        cursor.fail(start_token,
                    what + ": layer_bend_start: expected a fraction in [0, 1], got " + detail::quoted(start_token));
      lifts.layer_bends.push_back(bend);
      lifts.layer_bend_starts.push_back(start);
    }
    if (const std::string_view extra = detail::LineCursor::take_token(rest); !extra.empty())
      cursor.fail(extra, what + ": expected " + std::to_string(columns) +
                             (!lifts.layered ? " values (id lift scale)"
                              : bent ? " values (id lift scale layer_turn layer_scale layer_yaw layer_bend "
                                       "layer_bend_start)"
                              : yawed ? " values (id lift scale layer_turn layer_scale layer_yaw)"
                                      : " values (id lift scale layer_turn layer_scale)") +
                             ", got more: " + detail::quoted(extra));
    lifts.ids.push_back(uint64_t(id));
    lifts.lifts.push_back(lift);
    lifts.scales.push_back(scale);
  }
  if ((long long)lifts.ids.size() != count)
    throw InputError(FileLoc{path, cursor.line_number()},
                     "feathers: expected " + std::to_string(count) + " feathers, got " +
                         std::to_string(lifts.ids.size()) + " (a truncated file?)");
  return lifts;
}

}  // namespace plume::io
