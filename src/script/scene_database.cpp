// The paper's database as a scene: an XML table of marker ids and resources (docs/scene-api.md, "The XML
// database"). A URL becomes a web card, a path an image or a looping video, each placed on its marker.
#include "detect/dictionary.hpp"
#include "media/media_path.hpp"
#include "script/scene_model.hpp"
#include "script/xml_reader.hpp"

#include <map>

namespace arwb::script {
namespace {

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\n' || s[a] == '\r')) ++a;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\n' || s[b - 1] == '\r')) --b;
  return s.substr(a, b - a);
}

bool only_blank(const std::string& s) { return trim(s).empty(); }

// A whole decimal integer ("7", "-1", "+3"), nothing else.
bool parse_int(const std::string& s, long long* out) {
  if (s.empty() || s.size() > 12) return false;
  size_t i = 0;
  bool neg = false;
  if (s[0] == '-' || s[0] == '+') {
    neg = s[0] == '-';
    i = 1;
  }
  if (i == s.size()) return false;
  long long v = 0;
  for (; i < s.size(); ++i) {
    if (s[i] < '0' || s[i] > '9') return false;
    v = v * 10 + (s[i] - '0');
  }
  *out = neg ? -v : v;
  return true;
}

std::string quoted(const std::string& s) {
  std::string t = s.size() > 40 ? s.substr(0, 37) + "..." : s;
  return "'" + t + "'";
}

}  // namespace

Status load_database(const std::string& display, const std::string& text, const std::filesystem::path& dir,
                     SceneDef* def, Reporter& reporter) {
  auto at = [&](int line) { return display + ":" + std::to_string(line) + ": "; };
  const Result<XmlElement> doc = parse_xml(text, display);
  if (!doc) return fail(doc.error());
  const XmlElement& root = *doc;
  if (root.name != "database")
    return fail(at(root.line) + "the root element must be <database>, not <" + root.name + ">");
  for (const auto& [k, v] : root.attributes) {
    if (k == "dictionary") {
      std::string err;
      const std::optional<Dictionary> d = dictionary_by_name(trim(v), &err);
      if (!d) return fail(at(root.line) + "dictionary: " + err);
      def->dictionary = trim(v);
      def->dict_name = d->name();
      def->dict_size = d->size();
    } else {
      reporter.report(1, at(root.line) + "unknown attribute '" + k + "' of <database> ignored");
    }
  }
  if (!only_blank(root.text)) reporter.report(1, at(root.line) + "text directly inside <database> is ignored");

  std::map<int, int> seen;   // id -> line of its first row
  for (const XmlElement& row : root.children) {
    if (row.name != "row") {
      reporter.report(1, at(row.line) + "unexpected element <" + row.name + "> ignored (rows are <row>)");
      continue;
    }
    int known_id = -1;   // the row's id once it is read and in the dictionary
    // A refused row keeps a row of its own in the Scene panel (skipped, with the reason), matching no marker.
    auto skip = [&](int line, const std::string& why) {
      const std::string msg = at(line) + why + "; row skipped";
      reporter.report(2, msg);
      Mapping bad;
      if (known_id >= 0) bad.ids.ranges.push_back({known_id, known_id});
      bad.line = row.line;
      bad.skipped = msg;
      def->mappings.push_back(std::move(bad));
    };
    for (const auto& a : row.attributes)
      reporter.report(1, at(row.line) + "unknown attribute '" + a.first + "' of <row> ignored");
    if (!only_blank(row.text)) reporter.report(1, at(row.line) + "text directly inside <row> is ignored");
    const XmlElement* id_el = nullptr;
    const XmlElement* res_el = nullptr;
    bool dup = false;
    for (const XmlElement& c : row.children) {
      if (c.name == "id") {
        dup = dup || id_el;
        id_el = id_el ? id_el : &c;
      } else if (c.name == "resource") {
        dup = dup || res_el;
        res_el = res_el ? res_el : &c;
      } else {
        reporter.report(1, at(c.line) + "unexpected element <" + c.name + "> in <row> ignored");
      }
      if (!c.children.empty()) reporter.report(1, at(c.line) + "elements inside <" + c.name + "> are ignored");
    }
    if (dup) {
      skip(row.line, "a row has one <id> and one <resource>");
      continue;
    }
    if (!id_el) {
      skip(row.line, "row without an <id>");
      continue;
    }
    const std::string id_text = trim(id_el->text);
    long long id = 0;
    if (!parse_int(id_text, &id)) {
      skip(id_el->line, "id " + quoted(id_text) + " is not an integer");
      continue;
    }
    if (std::string e = check_id(*def, id); !e.empty()) {
      skip(id_el->line, e);
      continue;
    }
    known_id = static_cast<int>(id);
    const std::string res = res_el ? trim(res_el->text) : std::string();
    if (res.empty()) {
      skip(res_el ? res_el->line : row.line, "row for id " + std::to_string(id) + " has no resource");
      continue;
    }
    Mapping m;
    m.ids.ranges.push_back({static_cast<int>(id), static_cast<int>(id)});
    m.line = row.line;
    m.place = PlaceSpec::defaults(PlaceKind::on_marker);
    m.media.source = res;
    if (res.find("://") != std::string::npos) {
      if (std::string e = media::check_url(res); !e.empty()) {
        skip(res_el->line, e);
        continue;
      }
      m.media.kind = MediaKind::web;
      m.media.url = res;
      m.media.title = media::url_host(res);
    } else {
      const media::CheckedPath cp = media::check_media_path(dir, res);
      if (!cp.ok()) {
        skip(res_el->line, cp.error);
        continue;
      }
      m.media.kind = cp.kind == media::MediaFileKind::video ? MediaKind::video : MediaKind::image;
      m.media.path = cp.path;
      m.media.loop = m.media.kind == MediaKind::video;
    }
    if (auto it = seen.find(static_cast<int>(id)); it != seen.end())
      reporter.report(1, at(row.line) + "id " + std::to_string(id) + " already has a row on line " +
                             std::to_string(it->second) + "; both are shown");
    else seen[static_cast<int>(id)] = row.line;
    def->mappings.push_back(std::move(m));
  }
  return {};
}

}  // namespace arwb::script
