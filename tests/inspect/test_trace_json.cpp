// trace_to_json: valid JSON (parsed here by nlohmann, which is strict: no NaN, no trailing commas) holding every
// stage, the markers and the candidates with their fates.
#include "detect/detector.hpp"
#include "synth/synth.hpp"
#include "inspect/trace_json.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

using namespace arwb;
using Json = nlohmann::ordered_json;
using test::parse;

namespace {

// How many elements of the array satisfy `pred`.
template <typename Pred>
size_t count_if(Json& array, Pred pred) {
  return array.is_array() ? size_t(std::count_if(array.begin(), array.end(), pred)) : 0;
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

TEST(TraceJson, TheParserTheTestsUseIsStrict) {
  EXPECT_TRUE(Json::accept(R"({"a":[1,-2.5e3,true,null,"x\"\u00e9"],"b":{}})"));
  EXPECT_FALSE(Json::accept(R"({"a":[1,2})"));
  EXPECT_FALSE(Json::accept(R"({"a":1,})"));
  EXPECT_FALSE(Json::accept(R"({"a":nan})"));
  EXPECT_FALSE(Json::accept("{\"a\":\"tab\there\"}"));
  EXPECT_FALSE(Json::accept(R"({"a":01})"));
}

TEST(TraceJson, FullTraceIsValidJsonWithEveryStageMarkersAndCandidates) {
  const Dictionary d = make_aruco_original();
  FrameTrace t;
  const auto markers = Detector({d}).detect(two_markers(d), &t, TraceLevel::full);
  ASSERT_EQ(markers.size(), 2u);
  const std::string text = trace_to_json(t);
  Json j = parse(text);
  ASSERT_TRUE(j.is_object()) << text;
  // The fields in the order the header documents.
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"level", "width", "height", "work_width", "work_height", "scale_x",
                                             "scale_y", "total_ms", "contours", "stages", "search", "markers",
                                             "candidates"}));
  EXPECT_EQ(j["level"], "full");
  // One image, no video: the whole frame was searched.
  EXPECT_EQ(j["search"]["whole"], true);
  ASSERT_EQ(j["search"]["regions"].size(), 1u);
  EXPECT_EQ(j["search"]["regions"][0], Json::array({0, 0, 640, 480}));
  EXPECT_EQ(j["search"]["factor"], 1);
  EXPECT_EQ(j["width"], 640);
  EXPECT_EQ(j["height"], 480);
  EXPECT_TRUE(j["total_ms"].is_number());
  Json& stages = j["stages"];
  for (int s = 0; s < kStageCount; ++s)
    EXPECT_EQ(count_if(stages, [&](Json& r) { return r["name"] == stage_name(Stage(s)); }), 1u)
        << stage_name(Stage(s));
  EXPECT_EQ(stages.size(), t.stages.size());
  // Markers with their corners, first in the array.
  Json& m = j["markers"];
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0]["id"], 12);
  EXPECT_EQ(m[0]["dict"], "ARUCO_ORIGINAL");
  ASSERT_EQ(m[0]["corners"].size(), 4u);
  for (Json& c : m[0]["corners"]) EXPECT_TRUE(c.size() == 2 && c[0].is_number() && c[1].is_number()) << c;
  EXPECT_EQ(m[1]["id"], 345);
  EXPECT_EQ(m[1]["dict"], "ARUCO_ORIGINAL");
  // One fate per candidate; the rejected black square names its stage and parameter.
  Json& cands = j["candidates"];
  ASSERT_EQ(cands.size(), t.candidates.size());
  EXPECT_EQ(count_if(cands, [](Json& c) { return c["fate"].is_object(); }), t.candidates.size());
  EXPECT_EQ(count_if(cands, [](Json& c) { return c["fate"]["stage"] == "accepted"; }), 2u);
  EXPECT_GE(count_if(cands, [](Json& c) {
              return c["fate"]["stage"] == "otsu" && c["fate"]["param"] == "otsu_min_stddev";
            }),
            1u);
  EXPECT_GE(count_if(cands,
                     [](Json& c) { return !c["per_rotation"].empty() && c["per_rotation"][0].contains("id"); }),
            1u);
  EXPECT_GE(count_if(cands, [](Json& c) { return c["bits"].size() > 1 && c["bits"][0] == "0000000"; }), 1u);
  // Contours are counted, their points left out.
  EXPECT_EQ(j["contours"], t.contours.size());
  EXPECT_LT(text.size(), 2000 + 600 * t.candidates.size());
}

TEST(TraceJson, SummaryEmptyAndOddTracesAreValidToo) {
  const Dictionary d = make_aruco_original();
  FrameTrace t;
  Detector({d}).detect(two_markers(d), &t, TraceLevel::summary);
  EXPECT_EQ(parse(trace_to_json(t))["level"], "summary");
  Detector({d}).detect(two_markers(d), &t, TraceLevel::off);
  EXPECT_TRUE(parse(trace_to_json(t)).is_object());
  EXPECT_TRUE(parse(trace_to_json(FrameTrace{})).is_object());
  // Messages with quotes and control characters, and non-finite numbers (as null), stay valid and read back.
  FrameTrace odd;
  CandidateRecord c;
  c.fate = Rejection{Stage::quad_fit, "", std::nan(""), std::numeric_limits<double>::infinity(),
                     "a \"quoted\"\tmessage\n\x01"};
  c.dict = "weird\\name";
  odd.candidates.push_back(c);
  Marker m;
  m.dict = "x\"y";
  m.corners[0] = cv::Point2f(std::numeric_limits<float>::infinity(), 0);
  odd.markers.push_back(m);
  Marker bad_utf8;
  bad_utf8.dict = "\xff\xfe";   // bytes from a file need not be UTF-8
  odd.markers.push_back(bad_utf8);
  Json j = parse(trace_to_json(odd));
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["candidates"][0]["fate"]["message"], "a \"quoted\"\tmessage\n\x01");
  EXPECT_TRUE(j["candidates"][0]["fate"]["value"].is_null());
  EXPECT_TRUE(j["candidates"][0]["fate"]["limit"].is_null());
  EXPECT_EQ(j["candidates"][0]["dict"], "weird\\name");
  EXPECT_EQ(j["markers"][0]["dict"], "x\"y");
  EXPECT_TRUE(j["markers"][0]["corners"][0][0].is_null());
  EXPECT_EQ(j["markers"][0]["corners"][0][1], 0);
  EXPECT_TRUE(j["markers"][1]["dict"].is_string());
}
