// trace_to_json: valid JSON (checked by a small strict parser here, no python needed) holding every stage,
// the markers and the candidates with their fates.
#include "detect/detector.hpp"
#include "synth/synth.hpp"
#include "detect/trace_json.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <limits>
#include <cstring>
#include <string>

using namespace arwb;

namespace {

// A strict recursive-descent JSON checker (RFC 8259 grammar, no extensions). Counts object keys by name so
// tests can ask how often a key occurs.
class JsonChecker {
 public:
  explicit JsonChecker(const std::string& s) : s_(s) {}
  bool valid() {
    ws();
    if (!value()) return false;
    ws();
    return i_ == s_.size();
  }
  std::string error_context() const { return s_.substr(i_ > 40 ? i_ - 40 : 0, 80); }

 private:
  const std::string& s_;
  size_t i_ = 0;

  void ws() {
    while (i_ < s_.size() && std::strchr(" \t\n\r", s_[i_])) ++i_;
  }
  bool lit(const char* w) {
    const size_t n = std::strlen(w);
    if (s_.compare(i_, n, w) != 0) return false;
    i_ += n;
    return true;
  }
  bool value() {
    if (i_ >= s_.size()) return false;
    switch (s_[i_]) {
      case '{': return object();
      case '[': return array();
      case '"': return string();
      case 't': return lit("true");
      case 'f': return lit("false");
      case 'n': return lit("null");
      default: return number();
    }
  }
  bool object() {
    ++i_;
    ws();
    if (i_ < s_.size() && s_[i_] == '}') return ++i_, true;
    for (;;) {
      ws();
      if (!string()) return false;
      ws();
      if (i_ >= s_.size() || s_[i_++] != ':') return false;
      ws();
      if (!value()) return false;
      ws();
      if (i_ >= s_.size()) return false;
      if (s_[i_] == '}') return ++i_, true;
      if (s_[i_++] != ',') return false;
    }
  }
  bool array() {
    ++i_;
    ws();
    if (i_ < s_.size() && s_[i_] == ']') return ++i_, true;
    for (;;) {
      ws();
      if (!value()) return false;
      ws();
      if (i_ >= s_.size()) return false;
      if (s_[i_] == ']') return ++i_, true;
      if (s_[i_++] != ',') return false;
    }
  }
  bool string() {
    if (i_ >= s_.size() || s_[i_] != '"') return false;
    for (++i_; i_ < s_.size(); ++i_) {
      const auto c = static_cast<unsigned char>(s_[i_]);
      if (c == '"') return ++i_, true;
      if (c < 0x20) return false;
      if (c == '\\') {
        if (++i_ >= s_.size()) return false;
        const char e = s_[i_];
        if (e == 'u') {
          for (int k = 0; k < 4; ++k)
            if (++i_ >= s_.size() || !std::isxdigit(static_cast<unsigned char>(s_[i_]))) return false;
        } else if (!std::strchr("\"\\/bfnrt", e)) {
          return false;
        }
      }
    }
    return false;
  }
  bool digits() {
    const size_t start = i_;
    while (i_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i_]))) ++i_;
    return i_ > start;
  }
  bool number() {
    if (i_ < s_.size() && s_[i_] == '-') ++i_;
    if (i_ < s_.size() && s_[i_] == '0') ++i_;
    else if (!digits()) return false;
    if (i_ < s_.size() && s_[i_] == '.' && (++i_, !digits())) return false;
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      if (!digits()) return false;
    }
    return true;
  }
};

bool valid_json(const std::string& s, std::string* where = nullptr) {
  JsonChecker c(s);
  const bool ok = c.valid();
  if (!ok && where) *where = c.error_context();
  return ok;
}

size_t count(const std::string& text, const std::string& part) {
  size_t n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

cv::Mat two_markers(const Dictionary& d) {
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  draw_marker(img, d, 12, project_square({200, 240}, 100, 20, 0, 0, 800));
  draw_marker(img, d, 345, project_square({460, 240}, 80, 0, 30, 0, 800));
  cv::Mat blank = img(cv::Rect(20, 400, 60, 60));
  blank.setTo(cv::Scalar(0, 0, 0));  // a black square: a quad that is no marker
  return img;
}

}  // namespace

TEST(JsonChecker, AcceptsJsonAndRejectsBrokenText) {
  EXPECT_TRUE(valid_json(R"({"a":[1,-2.5e3,true,null,"x\"\u00e9"],"b":{}})"));
  EXPECT_FALSE(valid_json(R"({"a":[1,2})"));
  EXPECT_FALSE(valid_json(R"({"a":1,})"));
  EXPECT_FALSE(valid_json(R"({"a":nan})"));
  EXPECT_FALSE(valid_json("{\"a\":\"tab\there\"}"));
  EXPECT_FALSE(valid_json(R"({"a":01})"));
}

TEST(TraceJson, FullTraceIsValidJsonWithEveryStageMarkersAndCandidates) {
  const Dictionary d = make_aruco_original();
  FrameTrace t;
  const auto markers = Detector({d}).detect(two_markers(d), &t, TraceLevel::full);
  ASSERT_EQ(markers.size(), 2u);
  const std::string j = trace_to_json(t);
  std::string where;
  ASSERT_TRUE(valid_json(j, &where)) << "near: " << where;
  EXPECT_EQ(j.front(), '{');
  EXPECT_NE(j.find(R"("level":"full")"), std::string::npos);
  EXPECT_NE(j.find(R"("width":640,"height":480)"), std::string::npos);
  EXPECT_NE(j.find(R"("total_ms":)"), std::string::npos);
  for (int s = 0; s < kStageCount; ++s)
    EXPECT_NE(j.find("{\"name\":\"" + std::string(stage_name(Stage(s))) + "\""), std::string::npos)
        << stage_name(Stage(s));
  EXPECT_EQ(count(j, "{\"name\":"), t.stages.size());
  // Markers with their corners, first in the array.
  EXPECT_NE(j.find(R"("markers":[{"id":12,"dict":"ARUCO_ORIGINAL","corners":[[)"), std::string::npos);
  EXPECT_NE(j.find(R"({"id":345,"dict":"ARUCO_ORIGINAL")"), std::string::npos);
  // One fate per candidate; the rejected black square names its stage and parameter.
  EXPECT_EQ(count(j, "\"fate\":{"), t.candidates.size());
  EXPECT_EQ(count(j, R"("fate":{"stage":"accepted")"), 2u);
  EXPECT_NE(j.find(R"("stage":"otsu","param":"otsu_min_stddev")"), std::string::npos);
  EXPECT_NE(j.find(R"("per_rotation":[{"id":)"), std::string::npos);
  EXPECT_NE(j.find(R"("bits":["0000000",)"), std::string::npos);
  // Contours are counted, their points left out.
  EXPECT_NE(j.find("\"contours\":" + std::to_string(t.contours.size())), std::string::npos);
  EXPECT_LT(j.size(), 2000 + 600 * t.candidates.size());
}

TEST(TraceJson, SummaryEmptyAndOddTracesAreValidToo) {
  const Dictionary d = make_aruco_original();
  FrameTrace t;
  Detector({d}).detect(two_markers(d), &t, TraceLevel::summary);
  EXPECT_TRUE(valid_json(trace_to_json(t)));
  EXPECT_NE(trace_to_json(t).find(R"("level":"summary")"), std::string::npos);
  Detector({d}).detect(two_markers(d), &t, TraceLevel::off);
  EXPECT_TRUE(valid_json(trace_to_json(t)));
  EXPECT_TRUE(valid_json(trace_to_json(FrameTrace{})));
  // Messages with quotes and control characters, and non-finite numbers, stay valid.
  FrameTrace odd;
  CandidateRecord c;
  c.fate = Rejection{Stage::quad_fit, "", std::nan(""), std::numeric_limits<double>::infinity(), "a \"quoted\"\tmessage\n\x01"};
  c.dict = "weird\\name";
  odd.candidates.push_back(c);
  Marker m;
  m.dict = "x\"y";
  m.corners[0] = cv::Point2f(std::numeric_limits<float>::infinity(), 0);
  odd.markers.push_back(m);
  std::string where;
  EXPECT_TRUE(valid_json(trace_to_json(odd), &where)) << where;
}
