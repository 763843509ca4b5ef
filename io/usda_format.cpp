// Strands as USD BasisCurves in the text `.usda` encoding, written as ../shared/FORMATS.md lays out
// (linear curves, widths, GroomAPI, extent) with the per-curve primvars Unreal's groom importer
// reads (it keeps only primvars named `groom_*`): `groom_group_id` (the hair group) and
// `groom_root_uv` (the root's UV on the emitter), beside `int64[] primvars:plume_id`, the 64-bit
// stable strand ids (Unreal's `groom_id` is a 32-bit int). Read back for the same subset: the
// BasisCurves prim's curveVertexCounts, points (a default value or the first time sample), widths
// (constant, uniform or vertex) and the strand ids.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "io/file_scan.h"
#include "io/strand_formats.h"

namespace plume::io::detail {
namespace {

// ---------------------------------------------------------------------------------------------
// Reading

enum class TokenKind { End, Punct, String, Number, Word, Path };

struct Token {
  TokenKind kind = TokenKind::End;
  std::string_view text;  // the string's contents without quotes, for strings
  int line = 0;
  int column = 0;
};

// Character classes inline: the lexer sees every byte of files with millions of numbers.
constexpr bool is_digit(char c) { return c >= '0' && c <= '9'; }
constexpr bool is_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
constexpr bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }
constexpr bool is_punct_char(char c) {
  return c == '(' || c == ')' || c == '[' || c == ']' || c == '{' || c == '}' || c == '=' || c == ',' || c == ':';
}
constexpr bool is_number_char(char c) { return is_digit(c) || is_letter(c) || c == '+' || c == '-' || c == '.'; }
constexpr bool is_word_char(char c) { return is_digit(c) || is_letter(c) || c == ':' || c == '.'; }

/// Splits usda text into tokens: punctuation ()[]{}=,: strings "..." / """...""", numbers,
/// words (identifiers, may contain : and .), <paths> and @assets@. `#` starts a comment.
class UsdaLexer {
 public:
  UsdaLexer(std::string_view text, const std::string &path, size_t start, int start_line)
      : text_(text), path_(path), pos_(start), line_(start_line), line_start_(start) {}

  const Token &peek() {
    if (!has_peeked_) {
      peeked_ = lex();
      has_peeked_ = true;
    }
    return peeked_;
  }
  Token next() {
    const Token token = peek();
    has_peeked_ = false;
    return token;
  }
  [[noreturn]] void fail(const Token &at, const std::string &message) const {
    throw InputError(FileLoc{path_, at.line, at.column}, message);
  }
  /// The message reads "context detail: expected 'c', got ...".
  Token expect_punct(char c, std::string_view context, std::string_view detail = {}) {
    const Token token = next();
    if (token.kind != TokenKind::Punct || token.text[0] != c)
      fail(token, std::string(context) + std::string(detail) + ": expected '" + c + "', got " + describe(token));
    return token;
  }
  static std::string describe(const Token &token) {
    if (token.kind == TokenKind::End) return "the end of the file";
    if (token.kind == TokenKind::String) return "the string " + quoted(token.text);
    return quoted(token.text);
  }

 private:
  Token lex() {
    for (;;) {
      while (pos_ < text_.size() && is_space(text_[pos_])) advance_char();
      if (pos_ < text_.size() && text_[pos_] == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
        continue;
      }
      break;
    }
    Token token;
    token.line = line_;
    token.column = int(pos_ - line_start_) + 1;
    if (pos_ >= text_.size()) return token;
    const char c = text_[pos_];
    const size_t start = pos_;
    if (is_punct_char(c)) {
      token.kind = TokenKind::Punct;
      token.text = text_.substr(pos_++, 1);
    } else if (c == '"' || c == '\'') {
      const bool triple = text_.substr(pos_, 3) == std::string_view(std::string(3, c));
      const std::string_view close = triple ? text_.substr(pos_, 3) : text_.substr(pos_, 1);
      pos_ += close.size();
      const size_t body = pos_;
      for (;;) {
        if (pos_ >= text_.size()) fail(token, "string: expected a closing quote, the file ends");
        if (text_[pos_] == '\\') {
          pos_ += 2;
          continue;
        }
        if (!triple && text_[pos_] == '\n') fail(token, "string: expected a closing quote on the same line");
        if (text_.substr(pos_, close.size()) == close) break;
        advance_char();
      }
      token.kind = TokenKind::String;
      token.text = text_.substr(body, pos_ - body);
      pos_ += close.size();
    } else if (c == '<' || c == '@') {
      const char end = c == '<' ? '>' : '@';
      ++pos_;
      while (pos_ < text_.size() && text_[pos_] != end && text_[pos_] != '\n') ++pos_;
      if (pos_ >= text_.size() || text_[pos_] != end) fail(token, std::string("expected '") + end + "' to close " + c);
      ++pos_;
      token.kind = TokenKind::Path;
      token.text = text_.substr(start, pos_ - start);
    } else if (is_digit(c) || c == '-' || c == '+' || c == '.') {
      while (pos_ < text_.size() && is_number_char(text_[pos_])) ++pos_;
      token.kind = TokenKind::Number;
      token.text = text_.substr(start, pos_ - start);
    } else if (is_letter(c)) {
      while (pos_ < text_.size() && is_word_char(text_[pos_])) ++pos_;
      token.kind = TokenKind::Word;
      token.text = text_.substr(start, pos_ - start);
    } else {
      fail(token, "expected a usda token, got " + quoted(text_.substr(pos_, 1)));
    }
    return token;
  }
  void advance_char() {
    if (text_[pos_] == '\n') {
      ++line_;
      line_start_ = pos_ + 1;
    }
    ++pos_;
  }

  std::string_view text_;
  std::string path_;
  size_t pos_;
  int line_;
  size_t line_start_;
  Token peeked_;
  bool has_peeked_ = false;
};

bool is_punct(const Token &token, char c) { return token.kind == TokenKind::Punct && token.text[0] == c; }

/// An attribute value of the curves prim, with where it was declared.
struct ArrayValue {
  bool integer = false;          // parsed exactly into `integers` (64-bit ids do not fit a double)
  /// What each number must be, checked as it is read (with its place) before any is narrowed to a
  /// float: coordinates within float range, widths >= 0 and within it.
  enum class Bound { none, coordinate, width } bound = Bound::none;
  std::vector<double> values;    // flattened tuples, when not integer
  std::vector<int64_t> integers;
  Token at;
  bool present = false;
  std::string interpolation;  // from the attribute's metadata, "" when not given
};

/// What one BasisCurves prim holds.
struct CurvesPrim {
  static ArrayValue integer_array() {
    ArrayValue array;
    array.integer = true;
    return array;
  }
  static ArrayValue bounded_array(ArrayValue::Bound bound) {
    ArrayValue array;
    array.bound = bound;
    return array;
  }
  Token at;  // the prim's name
  ArrayValue counts = integer_array();
  ArrayValue points = bounded_array(ArrayValue::Bound::coordinate), widths = bounded_array(ArrayValue::Bound::width);
  ArrayValue plume_ids = integer_array(), groom_ids = integer_array();
};

class UsdaReader {
 public:
  explicit UsdaReader(const std::string &path) : path_(path), text_(read_file_bytes(path)) {}

  StrandSet read() {
    parse();
    StrandSet strands = build(prims_[0]);
    for (size_t i = 1; i < prims_.size(); ++i) {
      const StrandSet more = build(prims_[i]);
      const int64_t base = strands.offsets.back();
      for (size_t s = 1; s < more.offsets.size(); ++s) strands.offsets.push_back(base + more.offsets[s]);
      strands.positions.insert(strands.positions.end(), more.positions.begin(), more.positions.end());
      if (strands.widths.empty() != more.widths.empty())
        fail(prims_[i].at, "BasisCurves: expected widths on every BasisCurves prim or on none");
      strands.widths.insert(strands.widths.end(), more.widths.begin(), more.widths.end());
      strands.ids.insert(strands.ids.end(), more.ids.begin(), more.ids.end());
    }
    return strands;
  }

  /// Each BasisCurves prim's name and strands, in file order.
  std::vector<std::pair<std::string, StrandSet>> read_prims() {
    parse();
    std::vector<std::pair<std::string, StrandSet>> prims;
    for (const CurvesPrim &prim : prims_) prims.emplace_back(std::string(prim.at.text), build(prim));
    return prims;
  }

 private:
  void parse() {
    const size_t first_newline = text_.find('\n');
    std::string_view first_line = std::string_view(text_).substr(0, first_newline);
    if (!first_line.empty() && first_line.back() == '\r') first_line.remove_suffix(1);
    if (first_line != "#usda 1.0")
      throw InputError(FileLoc{path_, 1, 1}, "first line: expected \"#usda 1.0\", got " + quoted(first_line));
    UsdaLexer lexer(text_, path_, first_newline == std::string::npos ? text_.size() : first_newline + 1, 2);
    if (is_punct(lexer.peek(), '(')) skip_group(lexer);
    while (lexer.peek().kind != TokenKind::End) parse_prim(lexer);
    if (prims_.empty()) throw InputError(FileLoc{path_}, "expected a BasisCurves prim, found none");
  }

  /// Skips a balanced (...), [...] or {...} group starting at the next token.
  static void skip_group(UsdaLexer &lexer) {
    const Token open = lexer.next();
    std::vector<char> closers{open.text[0] == '(' ? ')' : open.text[0] == '[' ? ']' : '}'};
    while (!closers.empty()) {
      const Token token = lexer.next();
      if (token.kind == TokenKind::End) lexer.fail(open, std::string("expected '") + closers.back() + "' to close this, the file ends");
      if (token.kind != TokenKind::Punct) continue;
      const char c = token.text[0];
      if (c == '(' || c == '[' || c == '{') closers.push_back(c == '(' ? ')' : c == '[' ? ']' : '}');
      else if (c == ')' || c == ']' || c == '}') {
        if (c != closers.back()) lexer.fail(token, std::string("expected '") + closers.back() + "', got '" + c + "'");
        closers.pop_back();
      }
    }
  }

  /// def|over|class [Type] "name" [(metadata)] { body }
  void parse_prim(UsdaLexer &lexer) {
    const Token specifier = lexer.next();
    if (specifier.kind != TokenKind::Word ||
        (specifier.text != "def" && specifier.text != "over" && specifier.text != "class"))
      lexer.fail(specifier, "expected a prim (def, over or class), got " + UsdaLexer::describe(specifier));
    std::string_view type;
    if (lexer.peek().kind == TokenKind::Word) type = lexer.next().text;
    const Token name = lexer.next();
    if (name.kind != TokenKind::String) lexer.fail(name, "prim: expected a quoted name, got " + UsdaLexer::describe(name));
    if (is_punct(lexer.peek(), '(')) skip_group(lexer);
    lexer.expect_punct('{', "prim \"" + std::string(name.text) + "\"");
    const bool is_curves = type == "BasisCurves";
    if (is_curves) {
      prims_.emplace_back();
      prims_.back().at = name;
    }
    for (;;) {
      const Token &token = lexer.peek();
      if (is_punct(token, '}')) {
        lexer.next();
        return;
      }
      if (token.kind == TokenKind::End) lexer.fail(token, "prim \"" + std::string(name.text) + "\": expected '}', the file ends");
      if (token.kind == TokenKind::Word && (token.text == "def" || token.text == "over" || token.text == "class"))
        parse_prim(lexer);
      else
        parse_property(lexer, is_curves);
    }
  }

  /// [qualifiers] type[[]] name [= value] [(metadata)]
  void parse_property(UsdaLexer &lexer, bool capture) {
    std::vector<Token> words;
    while (lexer.peek().kind == TokenKind::Word || is_punct(lexer.peek(), '[')) {
      if (is_punct(lexer.peek(), '[')) {
        if (words.empty()) break;
        lexer.next();
        lexer.expect_punct(']', "array type");
        continue;
      }
      words.push_back(lexer.next());
    }
    if (words.size() < 2)
      lexer.fail(words.empty() ? lexer.peek() : words.front(),
                 "expected a property (type name = value), got " + UsdaLexer::describe(words.empty() ? lexer.peek() : words.front()));
    const Token name = words.back();
    ArrayValue *target = nullptr;
    int tuple = 1;
    if (capture) {
      CurvesPrim &prim = prims_.back();
      if (name.text == "curveVertexCounts") target = &prim.counts;
      else if (name.text == "points" || name.text == "points.timeSamples") target = &prim.points, tuple = 3;
      else if (name.text == "widths") target = &prim.widths;
      else if (name.text == "primvars:plume_id") target = &prim.plume_ids;
      else if (name.text == "primvars:groom_id") target = &prim.groom_ids;
    }
    if (target && target->present) lexer.fail(name, std::string(name.text) + ": expected one value, found a second");
    if (is_punct(lexer.peek(), '=')) {
      lexer.next();
      if (target) {
        target->present = true;
        target->at = name;
        if (name.text.ends_with(".timeSamples"))
          parse_time_samples(lexer, *target, tuple);
        else
          parse_array(lexer, *target, tuple, name.text);
      } else {
        skip_value(lexer);
      }
    }
    if (is_punct(lexer.peek(), '(')) {
      if (target)
        parse_metadata(lexer, *target);
      else
        skip_group(lexer);
    }
  }

  static void skip_value(UsdaLexer &lexer) {
    const Token &token = lexer.peek();
    if (is_punct(token, '[') || is_punct(token, '(') || is_punct(token, '{'))
      skip_group(lexer);
    else if (token.kind == TokenKind::End || token.kind == TokenKind::Punct)
      lexer.fail(token, "expected a value, got " + UsdaLexer::describe(token));
    else
      lexer.next();
  }

  /// { time: [ ... ], ... }: keeps the first sample.
  void parse_time_samples(UsdaLexer &lexer, ArrayValue &target, int tuple) {
    lexer.expect_punct('{', "timeSamples");
    bool first = true;
    while (!is_punct(lexer.peek(), '}')) {
      const Token time = lexer.next();
      if (time.kind != TokenKind::Number) lexer.fail(time, "timeSamples: expected a time code, got " + UsdaLexer::describe(time));
      lexer.expect_punct(':', "timeSamples");
      if (first)
        parse_array(lexer, target, tuple, "points");
      else
        skip_value(lexer);
      first = false;
      if (is_punct(lexer.peek(), ',')) lexer.next();
      else if (!is_punct(lexer.peek(), '}')) lexer.fail(lexer.peek(), "timeSamples: expected ',' or '}', got " + UsdaLexer::describe(lexer.peek()));
    }
    lexer.next();
    if (first) lexer.fail(target.at, "points.timeSamples: expected at least one sample, got none");
  }

  double parse_number(UsdaLexer &lexer, std::string_view what, ArrayValue::Bound bound = ArrayValue::Bound::none) {
    const Token token = lexer.next();
    if (token.kind != TokenKind::Number) lexer.fail(token, std::string(what) + ": expected a number, got " + UsdaLexer::describe(token));
    double value = 0.0;
    std::string_view digits = token.text;
    if (digits.front() == '+') digits.remove_prefix(1);
    const NumberStatus status = parse_double(digits, value);
    if (status == NumberStatus::NotFinite) lexer.fail(token, std::string(what) + ": expected a finite number, got " + quoted(token.text));
    if (status == NumberStatus::NotANumber) lexer.fail(token, std::string(what) + ": expected a number, got " + quoted(token.text));
    if (bound == ArrayValue::Bound::coordinate && !fits_float(value))
      lexer.fail(token, std::string(what) + ": " + float_range_message(value));
    if (bound == ArrayValue::Bound::width && !valid_width(value)) lexer.fail(token, std::string(what) + ": " + width_message(value));
    return value;
  }

  int64_t parse_integer(UsdaLexer &lexer, std::string_view what) {
    const Token token = lexer.next();
    if (token.kind != TokenKind::Number) lexer.fail(token, std::string(what) + ": expected an integer, got " + UsdaLexer::describe(token));
    std::string_view digits = token.text;
    if (digits.front() == '+') digits.remove_prefix(1);
    int64_t value = 0;
    const auto result = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (result.ec == std::errc::result_out_of_range)
      lexer.fail(token, std::string(what) + ": expected a 64-bit integer, got " + quoted(token.text));
    if (result.ec != std::errc() || result.ptr != digits.data() + digits.size())
      lexer.fail(token, std::string(what) + ": expected an integer, got " + quoted(token.text));
    return value;
  }

  /// [ v, v, ... ] or [ (a, b, c), ... ] with `tuple` numbers per element.
  void parse_array(UsdaLexer &lexer, ArrayValue &target, int tuple, std::string_view name) {
    const std::string_view tuple_detail = tuple == 3 ? ": a tuple of 3" : ": a tuple of 2";
    lexer.expect_punct('[', name);
    while (!is_punct(lexer.peek(), ']')) {
      if (tuple > 1) {
        lexer.expect_punct('(', name, tuple_detail);
        for (int k = 0; k < tuple; ++k) {
          if (k > 0) lexer.expect_punct(',', name, tuple_detail);
          target.values.push_back(parse_number(lexer, name, target.bound));
        }
        lexer.expect_punct(')', name, tuple_detail);
      } else if (target.integer) {
        target.integers.push_back(parse_integer(lexer, name));
      } else {
        target.values.push_back(parse_number(lexer, name, target.bound));
      }
      if (is_punct(lexer.peek(), ',')) lexer.next();
      else if (!is_punct(lexer.peek(), ']'))
        lexer.fail(lexer.peek(), std::string(name) + ": expected ',' or ']', got " + UsdaLexer::describe(lexer.peek()));
    }
    lexer.next();
  }

  /// ( interpolation = "vertex" ... ): keeps the interpolation, skips the rest.
  void parse_metadata(UsdaLexer &lexer, ArrayValue &target) {
    lexer.expect_punct('(', "metadata");
    while (!is_punct(lexer.peek(), ')')) {
      const Token key = lexer.next();
      if (key.kind != TokenKind::Word) lexer.fail(key, "metadata: expected a key, got " + UsdaLexer::describe(key));
      lexer.expect_punct('=', "metadata " + std::string(key.text));
      if (key.text == "interpolation") {
        const Token value = lexer.next();
        if (value.kind != TokenKind::String) lexer.fail(value, "interpolation: expected a string, got " + UsdaLexer::describe(value));
        target.interpolation = std::string(value.text);
      } else {
        skip_value(lexer);
      }
    }
    lexer.next();
  }

  [[noreturn]] void fail(const Token &at, const std::string &message) const {
    throw InputError(FileLoc{path_, at.line, at.column}, message);
  }

  StrandSet build(const CurvesPrim &prim) const {
    const ArrayValue &counts_ = prim.counts, &points_ = prim.points, &widths_ = prim.widths;
    const ArrayValue &plume_ids_ = prim.plume_ids, &groom_ids_ = prim.groom_ids;
    const Token &curves_at_ = prim.at;
    if (!counts_.present) fail(curves_at_, "BasisCurves: expected int[] curveVertexCounts, found none");
    if (!points_.present) fail(curves_at_, "BasisCurves: expected point3f[] points, found none");
    const size_t point_num = points_.values.size() / 3;
    uint64_t counted = 0;
    for (size_t s = 0; s < counts_.integers.size(); ++s) {
      const int64_t count = counts_.integers[s];
      if (count < 2 || count > std::numeric_limits<int32_t>::max())
        fail(counts_.at, "curveVertexCounts[" + std::to_string(s) + "]: expected an integer >= 2 (linear curves) that fits int, got " +
                             std::to_string(count));
      counted += uint64_t(count);  // below 2^31 each: no list a file can hold overflows the sum
    }
    if (counted != point_num)
      fail(counts_.at, "curveVertexCounts: expected to add up to the " + std::to_string(point_num) + " points, got " +
                           std::to_string(counted));
    StrandSet strands;
    const size_t strand_num = counts_.integers.size();
    strands.offsets.resize(strand_num + 1);
    for (size_t s = 0; s < strand_num; ++s) strands.offsets[s + 1] = strands.offsets[s] + counts_.integers[s];
    strands.positions.resize(point_num);
    for (size_t p = 0; p < point_num; ++p)
      strands.positions[p] = Eigen::Vector3f(to_float(points_.values[3 * p]), to_float(points_.values[3 * p + 1]),
                                             to_float(points_.values[3 * p + 2]));
    if (widths_.present) {
      const std::vector<double> &w = widths_.values;  // each >= 0 within float range (Bound::width)
      const std::string &interpolation = widths_.interpolation.empty() ? std::string("vertex") : widths_.interpolation;
      strands.widths.resize(point_num);
      if (interpolation == "constant" && w.size() == 1) {
        std::fill(strands.widths.begin(), strands.widths.end(), to_float(w[0]));
      } else if (interpolation == "uniform" && w.size() == strand_num) {
        for (size_t s = 0; s < strand_num; ++s)
          std::fill(strands.widths.begin() + strands.offsets[s], strands.widths.begin() + strands.offsets[s + 1], to_float(w[s]));
      } else if ((interpolation == "vertex" || interpolation == "varying") && w.size() == point_num) {
        for (size_t p = 0; p < point_num; ++p) strands.widths[p] = to_float(w[p]);
      } else {
        fail(widths_.at, "widths: expected 1 (constant), " + std::to_string(strand_num) + " (uniform) or " +
                             std::to_string(point_num) + " (vertex) values matching interpolation \"" + interpolation +
                             "\", got " + std::to_string(w.size()));
      }
    }
    strands.ids.resize(strand_num);
    // Plume's own stable ids first; a file from another tool may carry its ids as groom_id only.
    const ArrayValue *ids = plume_ids_.present ? &plume_ids_ : groom_ids_.present ? &groom_ids_ : nullptr;
    if (ids) {
      const std::string name(ids->at.text);
      if (ids->integers.size() != strand_num)
        fail(ids->at, name + ": expected one per curve (" + std::to_string(strand_num) + "), got " +
                          std::to_string(ids->integers.size()));
      for (size_t s = 0; s < strand_num; ++s) {
        const int64_t id = ids->integers[s];
        if (id < 0) fail(ids->at, name + "[" + std::to_string(s) + "]: expected an integer >= 0, got " + std::to_string(id));
        strands.ids[s] = uint64_t(id);
      }
    } else {
      for (size_t s = 0; s < strand_num; ++s) strands.ids[s] = s;
    }
    return strands;
  }

  std::string path_;
  std::string text_;
  std::vector<CurvesPrim> prims_;  // every BasisCurves prim, in file order
};

// ---------------------------------------------------------------------------------------------
// Writing


}  // namespace

StrandSet read_usda(const std::string &path) { return UsdaReader(path).read(); }

std::vector<std::pair<std::string, StrandSet>> read_usda_prims(const std::string &path) {
  return UsdaReader(path).read_prims();
}

namespace {

/// The layer header: doc, defaultPrim, metersPerUnit, upAxis and, with a time code, the layer's
/// time range and rate; then the Groom Xform opens.
void append_layer_header(std::string &out, const StrandWriteOptions &options) {
  detail::append_layer_header(out, options.comment, options.meters_per_unit, options.up_axis, options.time_code,
                              options.fps);
  out += "def Xform \"Groom\" (\n    kind = \"component\"\n    prepend apiSchemas = [\"GroomAPI\"]\n)\n{\n";
}

/// One BasisCurves prim `name` under the Groom: linear curves, points (a time sample at the time
/// code, when there is one), vertex widths, extent, and the per-curve primvars Unreal reads
/// (`groom_group_id`, `groom_root_uv`) beside Plume's 64-bit stable ids (`plume_id`).
/// `group_ids` and `root_uvs` are empty or one per strand (checked by the caller).
void append_curves_prim(AtomicFile &file, std::string &out, const std::string &name, const StrandSet &strands,
                        std::span<const int32_t> group_ids, std::span<const Eigen::Vector2f> root_uvs,
                        const StrandWriteOptions &options) {
  const size_t strand_num = strands.strand_count();
  const bool has_widths = !strands.widths.empty();
  // Stable ids are 64-bit ((face << 24) | j); USD has no unsigned 64-bit primvar, so int64.
  if (!std::all_of(strands.ids.begin(), strands.ids.end(),
                   [](uint64_t id) { return id <= uint64_t(std::numeric_limits<int64_t>::max()); }))
    throw InputError(FileLoc{file.path()}, "primvars:plume_id: ids above 2^63-1 do not fit USD int64");

  Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();
  if (strands.point_count() > 0) {
    lo = hi = strands.positions[0];
    for (const Eigen::Vector3f &p : strands.positions) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const float max_width =
      has_widths ? *std::max_element(strands.widths.begin(), strands.widths.end()) : options.constant_width;
  const Eigen::Vector3f pad = Eigen::Vector3f::Constant(0.5f * max_width);
  lo -= pad;
  hi += pad;

  out += "    def BasisCurves ";
  append_string_literal(out, name);
  out += "\n    {\n";
  out += "        uniform token type = \"linear\"\n";
  out += "        uniform token wrap = \"nonperiodic\"\n";

  out += "        int[] curveVertexCounts = [";
  for (size_t s = 0; s < strand_num; ++s) {
    if (s > 0) out += ", ";
    append_number(out, (long long)strands.points_in(s));
    flush_block_if_full(file, out);
  }
  out += "]\n";

  const std::string time_prefix = [&] {
    std::string prefix;
    if (options.time_code) {
      prefix = "            ";
      append_number(prefix, *options.time_code);
      prefix += ": ";
    }
    return prefix;
  }();
  if (options.time_code)
    out += "        point3f[] points.timeSamples = {\n" + time_prefix + "[";
  else
    out += "        point3f[] points = [";
  for (size_t p = 0; p < strands.point_count(); ++p) {
    if (p > 0) out += ", ";
    append_tuple(out, strands.positions[p].data(), 3);
    flush_block_if_full(file, out);
  }
  out += options.time_code ? "],\n        }\n" : "]\n";

  out += "        float[] widths = [";
  if (has_widths) {
    for (size_t p = 0; p < strands.point_count(); ++p) {
      if (p > 0) out += ", ";
      append_number(out, strands.widths[p]);
      flush_block_if_full(file, out);
    }
    out += "] (\n            interpolation = \"vertex\"\n        )\n";
  } else {
    append_number(out, options.constant_width);
    out += "] (\n            interpolation = \"constant\"\n        )\n";
  }

  const float extent[6] = {lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z()};
  if (options.time_code)
    out += "        float3[] extent.timeSamples = {\n" + time_prefix + "[";
  else
    out += "        float3[] extent = [";
  append_tuple(out, extent, 3);
  out += ", ";
  append_tuple(out, extent + 3, 3);
  out += options.time_code ? "],\n        }\n" : "]\n";

  out += "        int[] primvars:groom_group_id = [";
  for (size_t s = 0; s < strand_num; ++s) {
    if (s > 0) out += ", ";
    append_number(out, (long long)(group_ids.empty() ? 0 : group_ids[s]));
    flush_block_if_full(file, out);
  }
  out += "] (\n            interpolation = \"uniform\"\n        )\n";

  out += "        int64[] primvars:plume_id = [";
  for (size_t s = 0; s < strand_num; ++s) {
    if (s > 0) out += ", ";
    append_number(out, (long long)strands.ids[s]);
    flush_block_if_full(file, out);
  }
  out += "] (\n            interpolation = \"uniform\"\n        )\n";

  if (!root_uvs.empty()) {
    out += "        texCoord2f[] primvars:groom_root_uv = [";
    for (size_t s = 0; s < strand_num; ++s) {
      if (s > 0) out += ", ";
      append_tuple(out, root_uvs[s].data(), 2);
      flush_block_if_full(file, out);
    }
    out += "] (\n            interpolation = \"uniform\"\n        )\n";
  }
  out += "    }\n";
}

}  // namespace

void write_usda(AtomicFile &file, const StrandSet &strands, const StrandWriteOptions &options) {
  std::string out;
  out.reserve(kWriteBlockBytes + 256);
  append_layer_header(out, options);
  append_curves_prim(file, out, "hair", strands, options.group_ids, options.root_uvs, options);
  out += "}\n";
  file.write(out);
}

void write_usda_groups(AtomicFile &file, std::span<const StrandGroup> groups, const StrandWriteOptions &options) {
  std::string out;
  out.reserve(kWriteBlockBytes + 256);
  append_layer_header(out, options);
  std::vector<int32_t> group_ids;
  for (const StrandGroup &group : groups) {
    group_ids.assign(group.strands->strand_count(), group.group_id);
    append_curves_prim(file, out, group.name, *group.strands, group_ids, group.root_uvs, options);
  }
  out += "}\n";
  file.write(out);
}

}  // namespace plume::io::detail
