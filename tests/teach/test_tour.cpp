// The teaching tour: the shipped assets/teaching/tour.txt reads without a complaint and follows the pipeline;
// a teacher's mistakes are reported with file and line and never blank the rest of the tour.
#include "detect/params.hpp"
#include "teach/tour.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <sstream>

using namespace arwb;

namespace {

const std::string kShipped = std::string(ARWB_SOURCE_DIR) + "/assets/teaching/tour.txt";

std::string joined(const std::vector<std::string>& errors) {
  std::string s;
  for (const auto& e : errors) s += e + "\n";
  return s;
}

bool has_error(const std::vector<std::string>& errors, const std::string& part) {
  for (const auto& e : errors)
    if (e.find(part) != std::string::npos) return true;
  return false;
}

int word_count(const std::string& text) {
  std::istringstream in(text);
  std::string w;
  int n = 0;
  while (in >> w) ++n;
  return n;
}

// A tour with a good overview and otsu step around whatever the test puts in the middle.
std::string tour_around(const std::string& middle) {
  return "# test tour\n"
         "[overview]\n"
         "title: Overview\n"
         "Intro text.\n"
         "\n" +
         middle +
         "[otsu]\n"
         "title: Otsu\n"
         "params: otsu_min_stddev\n"
         "Otsu text.\n";
}

}  // namespace

TEST(Tour, ShippedTourLoadsWithoutErrors) {
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  ASSERT_TRUE(load_tour(kShipped, &steps, &errors)) << joined(errors);
  EXPECT_TRUE(errors.empty()) << joined(errors);
}

TEST(Tour, ShippedTourHasOneStepPerStageInPipelineOrder) {
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  ASSERT_TRUE(load_tour(kShipped, &steps, &errors)) << joined(errors);
  ASSERT_EQ(steps.size(), size_t(kStageCount) + 3);
  EXPECT_EQ(steps.front().key, "overview");
  EXPECT_FALSE(steps.front().is_stage);
  // After the detector's stages, what the corners say in 3D (the pose and its ambiguity), then the summary.
  EXPECT_EQ(steps[steps.size() - 2].key, "pose");
  EXPECT_FALSE(steps[steps.size() - 2].is_stage);
  EXPECT_EQ(steps.back().key, "summary");
  EXPECT_FALSE(steps.back().is_stage);
  for (int i = 0; i < kStageCount; ++i) {
    const TourStep& s = steps[size_t(i) + 1];
    const Stage stage = static_cast<Stage>(i);
    EXPECT_TRUE(s.is_stage) << s.key;
    EXPECT_EQ(s.stage, stage) << s.key;
    EXPECT_EQ(s.key, stage_name(stage));
  }
}

TEST(Tour, ShippedStepsAreCompleteAndTheirParametersExist) {
  std::vector<TourStep> steps;
  ASSERT_TRUE(load_tour(kShipped, &steps, nullptr));
  for (const auto& s : steps) {
    EXPECT_FALSE(s.title.empty()) << s.key;
    EXPECT_FALSE(s.look.empty()) << s.key;
    EXPECT_GT(s.line, 0) << s.key;
    // A step is read aloud in about a minute: 60 to 140 words.
    const int words = word_count(s.text);
    EXPECT_GE(words, 60) << s.key;
    EXPECT_LE(words, 140) << s.key;
    EXPECT_EQ(s.text.find('\r'), std::string::npos) << s.key;
    for (const auto& p : s.params) EXPECT_NE(find_param(p), nullptr) << s.key << ": " << p;
  }
}

TEST(Tour, ParagraphsAndFieldsAreRead) {
  test::TempDir dir;
  const std::string path = dir.str("tour.txt");
  test::write_file(path,
                   "[adaptive_threshold]\n"
                   "title: Threshold\n"
                   "First line\n"
                   "  continues here.\n"
                   "# a comment inside a step\n"
                   "\n"
                   "Second paragraph.\n"
                   "params: threshold_offset,threshold_window_px  threshold_offset\n"
                   "look: the binary image\n");
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  ASSERT_TRUE(load_tour(path, &steps, &errors)) << joined(errors);
  EXPECT_TRUE(errors.empty()) << joined(errors);
  ASSERT_EQ(steps.size(), 1u);
  EXPECT_EQ(steps[0].title, "Threshold");
  EXPECT_EQ(steps[0].text, "First line continues here.\n\nSecond paragraph.");
  EXPECT_EQ(steps[0].params, (std::vector<std::string>{"threshold_offset", "threshold_window_px"}));
  EXPECT_EQ(steps[0].look, "the binary image");
  EXPECT_EQ(steps[0].line, 1);
  EXPECT_EQ(steps[0].stage, Stage::adaptive_threshold);
}

TEST(Tour, UnknownStageIsReportedWithFileAndLineAndOtherStepsSurvive) {
  test::TempDir dir;
  const std::string path = dir.str("tour.txt");
  // Line 6 is the misspelt header.
  test::write_file(path, tour_around("[otsuu]\n"
                                     "title: Typo\n"
                                     "This step is lost.\n"));
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  EXPECT_TRUE(load_tour(path, &steps, &errors));
  ASSERT_EQ(errors.size(), 1u) << joined(errors);
  EXPECT_TRUE(has_error(errors, "tour.txt:6: unknown stage 'otsuu'")) << joined(errors);
  EXPECT_TRUE(has_error(errors, "did you mean 'otsu'")) << joined(errors);
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_EQ(steps[0].key, "overview");
  EXPECT_EQ(steps[1].key, "otsu");
  EXPECT_EQ(steps[1].text, "Otsu text.");  // the refused step's lines went nowhere
  // "accepted" is a fate in the trace, not a stage of the tour.
  test::write_file(path, tour_around("[accepted]\ntitle: No\nText.\n"));
  errors.clear();
  EXPECT_TRUE(load_tour(path, &steps, &errors));
  EXPECT_TRUE(has_error(errors, "tour.txt:6: unknown stage 'accepted'")) << joined(errors);
  EXPECT_EQ(steps.size(), 2u);
}

TEST(Tour, UnknownParameterIsReportedAndTheStepKept) {
  test::TempDir dir;
  const std::string path = dir.str("tour.txt");
  test::write_file(path, tour_around("[bit_grid]\n"
                                     "title: Bits\n"
                                     "params: warp_margin_rate, warp_margin_rte\n"
                                     "Bit text.\n"));
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  EXPECT_TRUE(load_tour(path, &steps, &errors));
  ASSERT_EQ(errors.size(), 1u) << joined(errors);
  EXPECT_TRUE(has_error(errors, "tour.txt:8: unknown parameter 'warp_margin_rte'")) << joined(errors);
  EXPECT_TRUE(has_error(errors, "did you mean 'warp_margin_rate'")) << joined(errors);
  ASSERT_EQ(steps.size(), 3u);
  EXPECT_EQ(steps[1].key, "bit_grid");
  EXPECT_EQ(steps[1].params, std::vector<std::string>{"warp_margin_rate"});
  EXPECT_EQ(steps[1].text, "Bit text.");
}

TEST(Tour, TextBeforeTheFirstStepIsReportedOnce) {
  test::TempDir dir;
  const std::string path = dir.str("tour.txt");
  test::write_file(path, "# header\n\nStray words\nmore stray words\n" + tour_around(""));
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  EXPECT_TRUE(load_tour(path, &steps, &errors));
  ASSERT_EQ(errors.size(), 1u) << joined(errors);
  EXPECT_TRUE(has_error(errors, "tour.txt:3: text before the first step")) << joined(errors);
  EXPECT_EQ(steps.size(), 2u);
}

TEST(Tour, StepWithoutTitleOrTextIsReportedAndKept) {
  test::TempDir dir;
  const std::string path = dir.str("tour.txt");
  test::write_file(path, tour_around("[contours]\nOutline text.\n\n[size_filter]\ntitle: Size\n\n"
                                     "[quad_fit]\ntitle:\nQuad text.\n"));
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  EXPECT_TRUE(load_tour(path, &steps, &errors));
  EXPECT_EQ(errors.size(), 3u) << joined(errors);
  EXPECT_TRUE(has_error(errors, "tour.txt:6: step 'contours' has no title")) << joined(errors);
  EXPECT_TRUE(has_error(errors, "tour.txt:9: step 'size_filter' has no text")) << joined(errors);
  EXPECT_TRUE(has_error(errors, "tour.txt:12: step 'quad_fit' has no title")) << joined(errors);
  ASSERT_EQ(steps.size(), 5u);
  EXPECT_EQ(steps[1].title, "contours");  // the key stands in for the missing title
  EXPECT_EQ(steps[1].text, "Outline text.");
}

TEST(Tour, RepeatedStepIsReportedAndTheFirstKept) {
  test::TempDir dir;
  const std::string path = dir.str("tour.txt");
  test::write_file(path, tour_around("[overview]\ntitle: Again\nSecond intro.\n"));
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  EXPECT_TRUE(load_tour(path, &steps, &errors));
  EXPECT_TRUE(has_error(errors, "tour.txt:6: step 'overview' already given at line 2")) << joined(errors);
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_EQ(steps[0].title, "Overview");
}

TEST(Tour, MissingFileIsAnErrorNamingIt) {
  std::vector<TourStep> steps{TourStep{}};
  std::vector<std::string> errors;
  const std::string path = std::string(ARWB_SOURCE_DIR) + "/assets/teaching/no_such_tour.txt";
  EXPECT_FALSE(load_tour(path, &steps, &errors));
  EXPECT_TRUE(steps.empty());
  EXPECT_TRUE(has_error(errors, "no_such_tour.txt: no such file")) << joined(errors);
}

TEST(Tour, NoReadableStepIsFalse) {
  test::TempDir dir;
  const std::string path = dir.str("tour.txt");
  test::write_file(path, "# only comments\n[otsuu]\ntitle: x\ntext\n");
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  EXPECT_FALSE(load_tour(path, &steps, &errors));
  EXPECT_TRUE(has_error(errors, "tour.txt:2: unknown stage 'otsuu'")) << joined(errors);
  EXPECT_TRUE(has_error(errors, "no step could be read")) << joined(errors);
}

TEST(Tour, Utf8TranslationIsKeptAndCrlfAndBomRemoved) {
  test::TempDir dir;
  const std::string path = dir.str("tour.txt");
  // A translation saved by a Windows editor: byte-order mark, CRLF line ends, accents and non-Latin script.
  test::write_file(path,
                   "\xEF\xBB\xBF# tour en fran\xC3\xA7" "ais\r\n"
                   "[overview]\r\n"
                   "title: Vue d'ensemble \xE2\x80\x94 \xE6\xA6\x82\xE8\xA6\x81\r\n"
                   "Le d\xC3\xA9tecteur lit les marqueurs.\r\n"
                   "look: l'\xC3\xA9tape \xC2\xAB seuil \xC2\xBB\r\n");
  std::vector<TourStep> steps;
  std::vector<std::string> errors;
  ASSERT_TRUE(load_tour(path, &steps, &errors)) << joined(errors);
  EXPECT_TRUE(errors.empty()) << joined(errors);
  ASSERT_EQ(steps.size(), 1u);
  EXPECT_EQ(steps[0].title, "Vue d'ensemble \xE2\x80\x94 \xE6\xA6\x82\xE8\xA6\x81");
  EXPECT_EQ(steps[0].text, "Le d\xC3\xA9tecteur lit les marqueurs.");
  EXPECT_EQ(steps[0].look, "l'\xC3\xA9tape \xC2\xAB seuil \xC2\xBB");
  EXPECT_EQ(steps[0].line, 2);
}
