#include "detect/trace_json.hpp"

#include "base/json.hpp"

namespace arwb {
namespace {

using json::number;
using json::quote;

// Helpers append rather than prepend ("[" + str): g++ 12 warns falsely (-Wrestrict) on literal + string.
void point(std::string& s, cv::Point2f p) {
  s += '[';
  s += number(p.x);
  s += ',';
  s += number(p.y);
  s += ']';
}

std::string quad(const Quad& q) {
  std::string s = "[";
  for (size_t k = 0; k < 4; ++k) {
    if (k) s += ',';
    point(s, q[k]);
  }
  return s += ']';
}

std::string size_or_null(const cv::Mat& m) {
  if (m.empty()) return "null";
  std::string s = "[";
  s += std::to_string(m.cols);
  s += ',';
  s += std::to_string(m.rows);
  return s += ']';
}

// The bit grid row by row as "0"/"1" strings: small, and readable in a text editor.
std::string bits(const cv::Mat& b) {
  if (b.empty() || b.type() != CV_8UC1) return "null";
  std::string s = "[";
  for (int y = 0; y < b.rows; ++y) {
    std::string row;
    for (int x = 0; x < b.cols; ++x) row += b.at<uint8_t>(y, x) ? '1' : '0';
    if (y) s += ',';
    s += quote(row);
  }
  return s += ']';
}

}  // namespace

std::string trace_to_json(const FrameTrace& t) {
  std::string s = "{\"level\":" + quote(trace_level_name(t.level)) + ",\"width\":" + std::to_string(t.width) +
                  ",\"height\":" + std::to_string(t.height) + ",\"work_width\":" + std::to_string(t.work_width) +
                  ",\"work_height\":" + std::to_string(t.work_height) + ",\"scale_x\":" + number(t.scale_x, 6) +
                  ",\"scale_y\":" + number(t.scale_y, 6) + ",\"total_ms\":" + number(t.total_ms) +
                  ",\"contours\":" + std::to_string(t.contours.size()) + ",\"stages\":[";
  for (size_t i = 0; i < t.stages.size(); ++i) {
    const StageRecord& r = t.stages[i];
    s += std::string(i ? "," : "") + "{\"name\":" + quote(stage_name(r.stage)) + ",\"ms\":" + number(r.ms) +
         ",\"in\":" + std::to_string(r.in) + ",\"out\":" + std::to_string(r.out) + ",\"image\":" +
         size_or_null(r.image) + "}";
  }
  s += "],\"markers\":[";
  for (size_t i = 0; i < t.markers.size(); ++i) {
    const Marker& m = t.markers[i];
    s += std::string(i ? "," : "") + "{\"id\":" + std::to_string(m.id) + ",\"dict\":" + quote(m.dict) +
         ",\"corners\":" + quad(m.corners) + ",\"hamming\":" + std::to_string(m.hamming) +
         ",\"rotation\":" + std::to_string(m.rotation) + "}";
  }
  s += "],\"candidates\":[";
  for (size_t i = 0; i < t.candidates.size(); ++i) {
    const CandidateRecord& c = t.candidates[i];
    s += std::string(i ? "," : "") + "{\"contour\":" + std::to_string(c.contour) + ",\"bbox\":[" +
         std::to_string(c.bbox.x) + "," + std::to_string(c.bbox.y) + "," + std::to_string(c.bbox.width) + "," +
         std::to_string(c.bbox.height) + "],\"perimeter\":" + number(c.perimeter) +
         ",\"quad\":" + (c.has_quad ? quad(c.quad) : "null") + ",\"otsu_threshold\":" +
         std::to_string(c.otsu_threshold) + ",\"stddev\":" + number(c.stddev) +
         ",\"border_errors\":" + std::to_string(c.border_errors) + ",\"border_cells\":" +
         std::to_string(c.border_cells) + ",\"dict\":" + quote(c.dict) + ",\"per_rotation\":[";
    // Rotations are only meaningful once identification ran (a dictionary was named).
    if (!c.dict.empty())
      for (size_t k = 0; k < 4; ++k)
        s += std::string(k ? "," : "") + "{\"id\":" + std::to_string(c.per_rotation[k].id) +
             ",\"distance\":" + std::to_string(c.per_rotation[k].hamming) + "}";
    s += "],\"marker\":" + std::to_string(c.marker) + ",\"warp\":" + size_or_null(c.warp) +
         ",\"bits\":" + bits(c.bits) + ",\"fate\":{\"stage\":" + quote(stage_name(c.fate.stage)) +
         ",\"param\":" + quote(c.fate.param) + ",\"value\":" + number(c.fate.value) +
         ",\"limit\":" + number(c.fate.limit) + ",\"message\":" + quote(c.fate.message) + "}}";
  }
  return s + "]}";
}

}  // namespace arwb
