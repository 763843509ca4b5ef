#include "app/view_page.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "groom/error.h"
#include "io/atomic_file.h"

namespace plume {

void JsonWriter::separate() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!first_.empty()) {
    if (!first_.back()) text_ += ',';
    first_.back() = false;
  }
}

JsonWriter &JsonWriter::begin_object() {
  separate();
  text_ += '{';
  first_.push_back(true);
  return *this;
}

JsonWriter &JsonWriter::end_object() {
  text_ += '}';
  first_.pop_back();
  return *this;
}

JsonWriter &JsonWriter::begin_array() {
  separate();
  text_ += '[';
  first_.push_back(true);
  return *this;
}

JsonWriter &JsonWriter::end_array() {
  text_ += ']';
  first_.pop_back();
  return *this;
}

JsonWriter &JsonWriter::key(std::string_view name) {
  value(name);
  text_ += ':';
  after_key_ = true;
  return *this;
}

JsonWriter &JsonWriter::value(std::string_view text) {
  separate();
  text_ += '"';
  for (const char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      text_ += '\\';
      text_ += c;
    } else if (u < 0x20 || c == '<' || c == '>' || c == '&') {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(u));
      text_ += escaped;
    } else {
      text_ += c;
    }
  }
  text_ += '"';
  return *this;
}

JsonWriter &JsonWriter::value(double number) {
  if (!std::isfinite(number)) throw InternalError("JsonWriter: a number that is not finite");
  separate();
  char digits[32];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(digits, sizeof digits, "%.*g", precision, number);
    if (std::strtod(digits, nullptr) == number) break;
  }
  text_ += digits;
  return *this;
}

JsonWriter &JsonWriter::value(float number) {
  if (!std::isfinite(number)) throw InternalError("JsonWriter: a number that is not finite");
  separate();
  char digits[32];
  for (int precision = 1; precision <= 9; ++precision) {
    std::snprintf(digits, sizeof digits, "%.*g", precision, double(number));
    if (std::strtof(digits, nullptr) == number) break;
  }
  text_ += digits;
  return *this;
}

JsonWriter &JsonWriter::value(int64_t number) {
  separate();
  text_ += std::to_string(number);
  return *this;
}

JsonWriter &JsonWriter::value(bool flag) {
  separate();
  text_ += flag ? "true" : "false";
  return *this;
}

JsonWriter &JsonWriter::null() {
  separate();
  text_ += "null";
  return *this;
}

int ViewBlob::add_bytes(const char *type, const void *data, size_t count, size_t element_size) {
  static_assert(std::endian::native == std::endian::little, "the page's arrays are little-endian");
  bytes_.resize((bytes_.size() + 7) / 8 * 8, 0);
  const size_t offset = bytes_.size();
  bytes_.resize(offset + count * element_size);
  if (count > 0) std::memcpy(bytes_.data() + offset, data, count * element_size);
  entries_.push_back({type, offset, count});
  return int(entries_.size()) - 1;
}

void ViewBlob::describe(JsonWriter &json) const {
  json.begin_array();
  for (const Entry &entry : entries_)
    json.begin_object().key("type").value(entry.type).key("offset").value(entry.offset).key("length").value(entry.length).end_object();
  json.end_array();
}

namespace {

constexpr char kBase64Digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// Base64 of `data` appended to `r_text`; `data` is a multiple of 3 bytes unless it is the end.
void append_base64(const uint8_t *data, size_t size, std::string &r_text) {
  size_t i = 0;
  for (; i + 3 <= size; i += 3) {
    const uint32_t v = uint32_t(data[i]) << 16 | uint32_t(data[i + 1]) << 8 | uint32_t(data[i + 2]);
    r_text += kBase64Digits[v >> 18];
    r_text += kBase64Digits[(v >> 12) & 63];
    r_text += kBase64Digits[(v >> 6) & 63];
    r_text += kBase64Digits[v & 63];
  }
  if (i < size) {
    const uint32_t v = uint32_t(data[i]) << 16 | (i + 1 < size ? uint32_t(data[i + 1]) << 8 : 0u);
    r_text += kBase64Digits[v >> 18];
    r_text += kBase64Digits[(v >> 12) & 63];
    r_text += i + 1 < size ? kBase64Digits[(v >> 6) & 63] : '=';
    r_text += '=';
  }
}

std::string html_escape(std::string_view text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

std::string base64(std::span<const uint8_t> data) {
  std::string text;
  text.reserve((data.size() + 2) / 3 * 4);
  append_base64(data.data(), data.size(), text);
  return text;
}

void write_view_page(const std::string &path, const std::string &title, const std::string &manifest_json,
                     const ViewBlob &blob) {
  const ViewerAssets &assets = viewer_assets();
  if (assets.script.empty())
    throw InternalError("this plume was built without the viewer's script (viewer/node_modules was missing when it "
                        "was built): run `npm ci` in viewer/ and build again, as ./dev.sh does");
  if (manifest_json.size() < 2 || manifest_json.front() != '{' || manifest_json.back() != '}')
    throw InternalError("write_view_page: the manifest is not a JSON object");
  JsonWriter buffers;
  blob.describe(buffers);

  io::AtomicFile file(path);
  file.write("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
             "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
             "<meta name=\"generator\" content=\"plume " PLUME_VERSION "\">\n<title>");
  file.write(html_escape(title));
  file.write("</title>\n</head>\n<body>\n<script type=\"application/json\" id=\"plume-scene\">");
  file.write(std::string_view(manifest_json).substr(0, manifest_json.size() - 1));
  file.write(manifest_json.size() > 2 ? ",\"buffers\":" : "\"buffers\":");
  file.write(buffers.text());
  file.write("}</script>\n<script type=\"application/octet-stream\" id=\"plume-data\">");
  // Base64 in chunks of 3 MB of data, so that memory does not double for a big page.
  const std::vector<uint8_t> &bytes = blob.bytes();
  constexpr size_t kChunk = size_t(3) << 20;
  std::string text;
  for (size_t at = 0; at < bytes.size(); at += kChunk) {
    text.clear();
    append_base64(bytes.data() + at, std::min(kChunk, bytes.size() - at), text);
    file.write(text);
  }
  file.write("</script>\n<!--\nThe script below is Plume's viewer, bundled with three.js ");
  file.write(assets.three_version);
  file.write(" (https://threejs.org), whose licence follows.\n\n");
  std::string license(assets.three_license);
  for (size_t at = license.find("--"); at != std::string::npos; at = license.find("--", at)) license.replace(at, 2, "- -");
  file.write(license);
  file.write("\n-->\n<script>");
  file.write(assets.script);
  file.write("</script>\n</body>\n</html>\n");
  file.commit();
}

}  // namespace plume
