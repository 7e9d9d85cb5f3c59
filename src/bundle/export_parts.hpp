// What `arwb export`'s files share (internal to src/bundle):
//   plan.cpp       plan_export: the checks, the files listed with their digests, the README and the manifest
//   self_test.cpp  each mapped id drawn, detected and run through the scene
//   phone_media.cpp  with --web: the scene's media a phone's browser would not show, said or converted
//   write.cpp      where the bundle goes (--out) and what it may replace; write_export, all or nothing
#pragma once

#include "bundle/bundle.hpp"

#include "calibration/calibration_file.hpp"
#include "detect/dictionary.hpp"
#include "workbench/scene_stage.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace arwb::bundle {

inline constexpr std::uint64_t kMaxSourceBytes = 4ull << 30;   // one file of the scene, read whole to digest it
inline constexpr std::uint64_t kMaxManifestBytes = 16u << 20;

// A line of progress, when the caller asked for them.
void say(const ExportOptions& o, const std::string& line);

// Whether --out names a zip (it ends in .arwb or .zip, in any case).
bool is_zip_name(const std::string& out);
// --out as an absolute path without a trailing '/' ("museum/" names the folder museum).
std::filesystem::path out_path(const std::string& out);
// The extension in lower case (".yml").
std::string lower_ext(const std::filesystem::path& p);
// --out named, its folder there, and an existing one replaced only with --force and only when it is a bundle.
Status check_out(const ExportOptions& o);

// The ids of the mapping as a sorted list (ranges expanded).
std::vector<int> expand(const std::vector<std::pair<int, int>>& ranges);

struct TestResult {
  std::vector<SelfTestRow> rows;
  std::vector<WebCard> cards;                       // picture: the PNG's bytes until the paths are given
  std::vector<std::string> card_png;
  bool passed = true;
};

// Each id the scene maps, drawn alone on a frame, detected with the scene's dictionary and run through the
// scene as the workbench does (SceneStage, offline media): every mapping that covers it must fire.
Result<TestResult> self_test(SceneStage& stage, const Dictionary& dict, const std::optional<Calibration>& calib,
                             const ExportOptions& options);

// With --web: each scene file a phone's browser would not show or play, as a warning naming it and why, or with
// convert_for_phones as a copy it does at web/phone/<path>.png or .mp4 (plan.generated, manifest.phone_media).
Status add_phone_media(ExportPlan& plan);

}  // namespace arwb::bundle
