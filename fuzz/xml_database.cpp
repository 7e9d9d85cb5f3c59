// Fuzz target: the paper's XML database (src/script/xml_reader.cpp, src/script/scene_database.cpp) from text in
// memory, as SceneRuntime::load reads a .xml scene: the strict XML reader, then the rows, ids, URLs and media
// paths. Media paths resolve in scripts/museum, a real scene folder (read only: its media headers are read, nothing
// is written), so rows can succeed as well as fail. Every failure has a message; a row kept has a resource.
#include "script/scene_model.hpp"
#include "script/xml_reader.hpp"

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

namespace {

struct Quiet : arwb::script::Reporter {
  void report(int level, const std::string& text) override {
    if (level < 0 || level > 2 || text.empty()) std::abort();
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const arwb::Result<arwb::script::XmlElement> doc = arwb::script::parse_xml(text, "fuzz.xml");
  if (!doc && doc.error().rfind("fuzz.xml", 0) != 0) std::abort();   // messages name the file

  static const std::filesystem::path dir = std::filesystem::path(ARWB_SOURCE_DIR) / "scripts" / "museum";
  arwb::script::SceneDef def;
  Quiet reporter;
  const arwb::Status st = arwb::script::load_database("fuzz.xml", text, dir, &def, reporter);
  if (!st && st.error().empty()) std::abort();
  // A row in use has its id and resource; a refused one keeps a row that says why (and runs nothing).
  for (const arwb::script::Mapping& m : def.mappings)
    if (m.skipped.empty() ? m.media.source.empty() || m.ids.ranges.empty() : m.skipped.find("fuzz.xml") != 0)
      std::abort();
  return 0;
}
