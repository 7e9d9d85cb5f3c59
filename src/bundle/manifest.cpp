// manifest.json: written by manifest_json, read back by parse_manifest, which trusts nothing in it (a bundle is
// a file someone sent): every field's type, the format version, relative paths and hex digests are checked, and
// the first bad one is named.
#include "bundle/bundle.hpp"
#include "bundle/bundle_files.hpp"
#include "base/files.hpp"
#include "base/json_depth.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <set>

namespace arwb::bundle {

using nlohmann::json;

std::string manifest_json(const Manifest& m) {
  // Written in the order a reader wants it (the version first), not sorted by key.
  nlohmann::ordered_json j;
  j["format_version"] = m.format_version;
  j["title"] = m.title;
  j["generator"] = m.generator;
  j["dictionary"] = m.dictionary;
  j["ids"] = m.ids;
  j["marker_size_mm"] = m.marker_size_mm;
  j["scene"] = m.scene;
  j["calibration"] = m.calibration;
  nlohmann::ordered_json files = nlohmann::ordered_json::array();
  for (const BundleFile& f : m.files)
    files.push_back({{"path", f.path}, {"size", f.size}, {"sha256", f.sha256}, {"role", f.role}});
  j["files"] = files;
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const SelfTestRow& r : m.self_test)
    rows.push_back({{"id", r.id}, {"line", r.mapping_line}, {"media", r.media}, {"detected", r.detected},
                    {"fired", r.fired}, {"detail", r.detail}});
  j["self_test"] = rows;
  j["self_test_passed"] = m.self_test_passed;
  nlohmann::ordered_json cards = nlohmann::ordered_json::array();
  for (const WebCard& c : m.web_cards) cards.push_back({{"url", c.url}, {"title", c.title}, {"picture", c.picture}});
  j["web_cards"] = cards;
  if (!m.phone_media.empty()) {
    nlohmann::ordered_json copies = nlohmann::ordered_json::array();
    for (const PhoneCopy& c : m.phone_media)
      copies.push_back({{"path", c.path}, {"phone", c.phone}, {"reason", c.reason}});
    j["phone_media"] = copies;
  }
  // Invalid UTF-8 (a title from a command line) is replaced, never a reason to fail.
  return json_text(j, 2) + "\n";
}

namespace {

constexpr int kMaxDepth = 16;

struct Reader {
  std::string error;
  bool bad(const std::string& field, const std::string& why) {
    if (error.empty()) error = std::string(kManifestName) + ": " + field + ": " + why;
    return false;
  }
  bool str(const json& o, const char* key, const std::string& field, std::string* out) {
    const auto it = o.find(key);
    if (it == o.end()) return bad(field, "missing");
    if (!it->is_string()) return bad(field, "not a string");
    *out = it->get<std::string>();
    return true;
  }
  bool boolean(const json& o, const char* key, const std::string& field, bool* out) {
    const auto it = o.find(key);
    if (it == o.end()) return bad(field, "missing");
    if (!it->is_boolean()) return bad(field, "not true or false");
    *out = it->get<bool>();
    return true;
  }
  bool integer(const json& o, const char* key, const std::string& field, long long lo, long long hi, long long* out) {
    const auto it = o.find(key);
    if (it == o.end()) return bad(field, "missing");
    if (!it->is_number_integer()) return bad(field, "not a whole number");
    const long long v = it->is_number_unsigned() && it->get<unsigned long long>() > (unsigned long long)hi
                            ? hi + 1
                            : it->get<long long>();
    if (v < lo || v > hi) return bad(field, std::to_string(v) + " is out of range " + std::to_string(lo) + ".." +
                                                std::to_string(hi));
    *out = v;
    return true;
  }
  bool array(const json& o, const char* key, const std::string& field, const json** out) {
    const auto it = o.find(key);
    if (it == o.end()) return bad(field, "missing");
    if (!it->is_array()) return bad(field, "not a list");
    *out = &*it;
    return true;
  }
  bool path(const std::string& p, const std::string& field, bool may_be_empty) {
    if (p.empty() && may_be_empty) return true;
    const std::string problem = bundle_path_problem(p);
    if (!problem.empty()) return bad(field, quoted_name(p) + ": " + problem);
    return true;
  }
};

bool is_hex64(const std::string& s) {
  if (s.size() != 64) return false;
  for (const char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

}  // namespace

Result<Manifest> parse_manifest(const std::string& text) {
  // Deeper nesting than a manifest ever has is refused before parsing.
  if (Status depth = check_json_depth(text, "", kMaxDepth); !depth)
    return fail(std::string(kManifestName) + ": " + depth.error());   // "manifest.json: line 3: nested deeper ..."
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    // Where the parser stopped, as a line and column a text editor shows (e.byte counts from 1).
    const size_t at = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    size_t line = 1, column = 1;
    for (size_t i = 0; i < at; ++i) {
      if (text[i] == '\n') ++line, column = 1;
      else if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) ++column;
    }
    return fail(std::string(kManifestName) + ": not valid JSON at line " + std::to_string(line) + ", column " +
                std::to_string(column) + " (byte " + std::to_string(e.byte) + ")");
  } catch (const json::out_of_range&) {
    // Valid syntax the parser still refuses: a number beyond a double ("9e8395"), found by fuzz/manifest as it
    // was by fuzz/model_file for glTF. Uncaught, it ended `arwb play` with the library's own text.
    return fail(std::string(kManifestName) + ": not valid JSON (a number too large for a double)");
  } catch (const json::exception& e) {
    return fail(std::string(kManifestName) + ": not valid JSON (" + shown_name(e.what()) + ")");
  }
  if (!j.is_object()) return fail(std::string(kManifestName) + ": not a JSON object");
  Reader r;
  Manifest m;
  long long v = 0;
  // The version first: a newer bundle may have other fields, and is refused for what it is.
  if (!r.integer(j, "format_version", "format_version", 1, 1'000'000, &v)) return fail(r.error);
  if (v > kFormatVersion)
    return fail(std::string(kManifestName) + ": format_version " + std::to_string(v) +
                ": made by a newer arwb (this one reads bundles up to version " + std::to_string(kFormatVersion) + ")");
  m.format_version = int(v);
  r.str(j, "title", "title", &m.title);
  r.str(j, "generator", "generator", &m.generator);
  r.str(j, "dictionary", "dictionary", &m.dictionary);
  const json* ids = nullptr;
  if (r.array(j, "ids", "ids", &ids))
    for (size_t i = 0; i < ids->size(); ++i) {
      const json& id = (*ids)[i];
      if (!id.is_number_integer() || id.get<long long>() < 0 || id.get<long long>() > 1'000'000) {
        r.bad("ids[" + std::to_string(i) + "]", "not a marker id");
        break;
      }
      m.ids.push_back(id.get<int>());
    }
  if (const auto it = j.find("marker_size_mm"); it == j.end()) r.bad("marker_size_mm", "missing");
  else if (!it->is_number() || !(it->get<double>() >= kMinMarkerSizeMm) || it->get<double>() > kMaxMarkerSizeMm)
    r.bad("marker_size_mm", "not a size of " + std::to_string(int(kMinMarkerSizeMm)) + " to " +
                                std::to_string(int(kMaxMarkerSizeMm)) + " mm");
  else m.marker_size_mm = it->get<double>();
  if (r.str(j, "scene", "scene", &m.scene)) r.path(m.scene, "scene", false);
  if (r.str(j, "calibration", "calibration", &m.calibration)) r.path(m.calibration, "calibration", true);
  const json* files = nullptr;
  std::set<std::string> paths;
  if (r.array(j, "files", "files", &files))
    for (size_t i = 0; i < files->size() && r.error.empty(); ++i) {
      const std::string field = "files[" + std::to_string(i) + "]";
      const json& f = (*files)[i];
      if (!f.is_object()) {
        r.bad(field, "not an object");
        break;
      }
      BundleFile b;
      long long size = 0;
      if (r.str(f, "path", field + ".path", &b.path) && r.path(b.path, field + ".path", false)) {
        if (b.path == kManifestName) r.bad(field + ".path", "lists manifest.json itself");
        else if (!paths.insert(b.path).second) r.bad(field + ".path", quoted_name(b.path) + " is listed twice");
      }
      if (r.integer(f, "size", field + ".size", 0, (1ll << 50), &size)) b.size = std::uint64_t(size);
      if (r.str(f, "sha256", field + ".sha256", &b.sha256) && !is_hex64(b.sha256))
        r.bad(field + ".sha256", "not 64 lowercase hex digits");
      r.str(f, "role", field + ".role", &b.role);
      m.files.push_back(std::move(b));
    }
  const json* rows = nullptr;
  if (r.array(j, "self_test", "self_test", &rows))
    for (size_t i = 0; i < rows->size() && r.error.empty(); ++i) {
      const std::string field = "self_test[" + std::to_string(i) + "]";
      const json& o = (*rows)[i];
      if (!o.is_object()) {
        r.bad(field, "not an object");
        break;
      }
      SelfTestRow row;
      long long n = 0;
      if (r.integer(o, "id", field + ".id", 0, 1'000'000, &n)) row.id = int(n);
      if (r.integer(o, "line", field + ".line", 0, 100'000'000, &n)) row.mapping_line = int(n);
      r.str(o, "media", field + ".media", &row.media);
      r.boolean(o, "detected", field + ".detected", &row.detected);
      r.boolean(o, "fired", field + ".fired", &row.fired);
      r.str(o, "detail", field + ".detail", &row.detail);
      m.self_test.push_back(std::move(row));
    }
  r.boolean(j, "self_test_passed", "self_test_passed", &m.self_test_passed);
  const json* cards = nullptr;
  if (r.array(j, "web_cards", "web_cards", &cards))
    for (size_t i = 0; i < cards->size() && r.error.empty(); ++i) {
      const std::string field = "web_cards[" + std::to_string(i) + "]";
      const json& o = (*cards)[i];
      if (!o.is_object()) {
        r.bad(field, "not an object");
        break;
      }
      WebCard c;
      r.str(o, "url", field + ".url", &c.url);
      r.str(o, "title", field + ".title", &c.title);
      if (r.str(o, "picture", field + ".picture", &c.picture)) r.path(c.picture, field + ".picture", false);
      m.web_cards.push_back(std::move(c));
    }
  const json* copies = nullptr;
  if (j.contains("phone_media") && r.array(j, "phone_media", "phone_media", &copies))
    for (size_t i = 0; i < copies->size() && r.error.empty(); ++i) {
      const std::string field = "phone_media[" + std::to_string(i) + "]";
      const json& o = (*copies)[i];
      if (!o.is_object()) {
        r.bad(field, "not an object");
        break;
      }
      PhoneCopy c;
      if (r.str(o, "path", field + ".path", &c.path)) r.path(c.path, field + ".path", false);
      if (r.str(o, "phone", field + ".phone", &c.phone)) r.path(c.phone, field + ".phone", false);
      r.str(o, "reason", field + ".reason", &c.reason);
      m.phone_media.push_back(std::move(c));
    }
  if (!r.error.empty()) return fail(r.error);
  // What the manifest points at must be among its files.
  if (!paths.count(m.scene)) return fail(std::string(kManifestName) + ": scene: " + quoted_name(m.scene) + " is not among files");
  if (!m.calibration.empty() && !paths.count(m.calibration))
    return fail(std::string(kManifestName) + ": calibration: " + quoted_name(m.calibration) + " is not among files");
  for (size_t i = 0; i < m.web_cards.size(); ++i)
    if (!paths.count(m.web_cards[i].picture))
      return fail(std::string(kManifestName) + ": web_cards[" + std::to_string(i) + "].picture: " +
                  quoted_name(m.web_cards[i].picture) + " is not among files");
  for (size_t i = 0; i < m.phone_media.size(); ++i)
    for (const auto& [key, path] : {std::pair{".path", &m.phone_media[i].path}, {".phone", &m.phone_media[i].phone}})
      if (!paths.count(*path))
        return fail(std::string(kManifestName) + ": phone_media[" + std::to_string(i) + "]" + key + ": " +
                    quoted_name(*path) + " is not among files");
  return m;
}

}  // namespace arwb::bundle
