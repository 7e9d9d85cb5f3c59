#include "inspect/trace_json.hpp"

#include "base/decimals.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>

namespace arwb {
namespace {

// ordered_json: fields come out in the order written here, the order the header documents.
using Json = nlohmann::ordered_json;

Json point(cv::Point2f p) { return Json::array({round_decimals(p.x, 3), round_decimals(p.y, 3)}); }

Json quad(const Quad& q) {
  Json a = Json::array();
  for (const auto& p : q) a.push_back(point(p));
  return a;
}

Json size_or_null(const cv::Mat& m) { return m.empty() ? Json(nullptr) : Json::array({m.cols, m.rows}); }

// The bit grid row by row as "0"/"1" strings: small, and readable in a text editor.
Json bits(const cv::Mat& b) {
  if (b.empty() || b.type() != CV_8UC1) return nullptr;
  Json rows = Json::array();
  for (int y = 0; y < b.rows; ++y) {
    std::string row;
    for (int x = 0; x < b.cols; ++x) row += b.at<uint8_t>(y, x) ? '1' : '0';
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

std::string trace_to_json(const FrameTrace& t) {
  Json j;
  j["level"] = trace_level_name(t.level);
  j["width"] = t.width;
  j["height"] = t.height;
  j["work_width"] = t.work_width;
  j["work_height"] = t.work_height;
  j["scale_x"] = round_decimals(t.scale_x, 6);
  j["scale_y"] = round_decimals(t.scale_y, 6);
  j["total_ms"] = round_decimals(t.total_ms, 3);
  j["contours"] = t.contours.size();
  Json& stages = j["stages"] = Json::array();
  for (const StageRecord& r : t.stages)
    stages.push_back({{"name", stage_name(r.stage)}, {"ms", round_decimals(r.ms, 3)}, {"in", r.in}, {"out", r.out},
                      {"image", size_or_null(r.image)}});
  Json regions = Json::array();
  for (const cv::Rect& r : t.search.regions) regions.push_back({r.x, r.y, r.width, r.height});
  j["search"] = {{"whole", t.search.whole}, {"factor", t.search.factor}, {"known", t.search.known},
                 {"why", t.search.why}, {"regions", std::move(regions)}};
  Json& markers = j["markers"] = Json::array();
  for (const Marker& m : t.markers)
    markers.push_back({{"id", m.id}, {"dict", m.dict}, {"corners", quad(m.corners)}, {"hamming", m.hamming},
                       {"rotation", m.rotation}});
  Json& candidates = j["candidates"] = Json::array();
  for (const CandidateRecord& c : t.candidates) {
    Json per_rotation = Json::array();
    // Rotations are only meaningful once identification ran (a dictionary was named).
    if (!c.dict.empty())
      for (const auto& r : c.per_rotation) per_rotation.push_back({{"id", r.id}, {"distance", r.hamming}});
    candidates.push_back({{"contour", c.contour},
                          {"bbox", {c.bbox.x, c.bbox.y, c.bbox.width, c.bbox.height}},
                          {"perimeter", round_decimals(c.perimeter, 3)},
                          {"quad", c.has_quad ? quad(c.quad) : Json(nullptr)},
                          {"otsu_threshold", c.otsu_threshold},
                          {"stddev", round_decimals(c.stddev, 3)},
                          {"border_errors", c.border_errors},
                          {"border_cells", c.border_cells},
                          {"dict", c.dict},
                          {"read_as_found", c.read_as_found},
                          {"local_thresholds", c.local_thresholds},
                          {"per_rotation", std::move(per_rotation)},
                          {"marker", c.marker},
                          {"warp", size_or_null(c.warp)},
                          {"bits", bits(c.bits)},
                          {"fate",
                           {{"stage", stage_name(c.fate.stage)},
                            {"param", c.fate.param},
                            {"value", round_decimals(c.fate.value, 3)},
                            {"limit", round_decimals(c.fate.limit, 3)},
                            {"message", c.fate.message}}}});
  }
  // Names and messages are bytes from files and users: invalid UTF-8 is replaced rather than thrown on.
  return json_text(j);
}

}  // namespace arwb
