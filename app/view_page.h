// The page `plume view` writes: one self-contained HTML file holding the viewer's JavaScript
// (three.js and viewer/src, bundled when Plume is built) and the scene: a JSON manifest and its
// arrays, little-endian binary in one base64 block. The format is in docs/viewer.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace plume {

/// A small JSON writer: values in order, commas and string escapes handled. Strings escape '<' so
/// that the text can sit inside an HTML <script> element.
class JsonWriter {
 public:
  JsonWriter &begin_object();
  JsonWriter &end_object();
  JsonWriter &begin_array();
  JsonWriter &end_array();
  /// The key of the next value, inside an object.
  JsonWriter &key(std::string_view name);
  JsonWriter &value(std::string_view text);
  JsonWriter &value(const char *text) { return value(std::string_view(text)); }
  JsonWriter &value(double number);  // finite; written with 17 significant digits at most
  JsonWriter &value(float number);   // finite; the shortest text that reads back as the same float
  JsonWriter &value(int64_t number);
  JsonWriter &value(int number) { return value(int64_t(number)); }
  JsonWriter &value(size_t number) { return value(int64_t(number)); }
  JsonWriter &value(bool flag);
  JsonWriter &null();
  const std::string &text() const { return text_; }

 private:
  void separate();
  std::string text_;
  std::vector<bool> first_;  // one per open object or array: no value in it yet
  bool after_key_ = false;
};

/// The arrays of a page: little-endian, each starting at a multiple of 8 bytes, named in the
/// manifest by their index.
class ViewBlob {
 public:
  int add(std::span<const float> values) { return add_bytes("f32", values.data(), values.size(), 4); }
  int add(std::span<const double> values) { return add_bytes("f64", values.data(), values.size(), 8); }
  int add(std::span<const uint32_t> values) { return add_bytes("u32", values.data(), values.size(), 4); }
  int add(std::span<const int32_t> values) { return add_bytes("i32", values.data(), values.size(), 4); }
  int add(std::span<const uint8_t> values) { return add_bytes("u8", values.data(), values.size(), 1); }
  size_t byte_count() const { return bytes_.size(); }
  const std::vector<uint8_t> &bytes() const { return bytes_; }
  /// Writes the "buffers" array: [{"type": "f32", "offset": bytes, "length": elements}, ...].
  void describe(JsonWriter &json) const;

 private:
  int add_bytes(const char *type, const void *data, size_t count, size_t element_size);
  struct Entry {
    const char *type;
    size_t offset, length;
  };
  std::vector<Entry> entries_;
  std::vector<uint8_t> bytes_;
};

/// The most data bytes a page holds: a browser reads the base64 block as one string, and Chromium's
/// longest string is 2^29 - 24 characters (512 MB of text for 384 MB of data).
inline constexpr size_t kMaxPageDataBytes = size_t(380) << 20;

/// The viewer's script as this build embedded it, with the version and licence of the three.js it
/// bundles. `script` is empty when the build found no viewer/node_modules (npm ci in viewer/).
struct ViewerAssets {
  std::string_view script;
  std::string_view three_version;
  std::string_view three_license;
};
const ViewerAssets &viewer_assets();

/// Writes the page atomically: `manifest_json` is a complete JSON object without "buffers", which
/// is added from `blob`. Throws InternalError when this build has no viewer script, InputError when
/// the file cannot be written.
void write_view_page(const std::string &path, const std::string &title, const std::string &manifest_json,
                     const ViewBlob &blob);

/// Standard base64 (RFC 4648, with padding) of `data`.
std::string base64(std::span<const uint8_t> data);

}  // namespace plume
