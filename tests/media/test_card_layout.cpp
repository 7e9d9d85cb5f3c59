// The text cards' layout without cairo (media/card_layout.hpp): its font table measures text as cairo does when
// hinting and hinted metrics are off (how cards.cpp draws), and the cards MediaStore draws have the layout's size,
// with their text's pixels inside the box the layout gives each line.
#include "media/card_layout.hpp"
#include "media/media_store.hpp"

#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace arwb::media {
namespace {

// cairo's own measure of `s` in DejaVu Sans at `px`, unhinted, as cards.cpp measured before the table.
struct CairoMeasure {
  cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1);
  cairo_t* cr = cairo_create(surface);
  CairoMeasure() {
    cairo_font_options_t* o = cairo_font_options_create();
    cairo_font_options_set_hint_metrics(o, CAIRO_HINT_METRICS_OFF);
    cairo_font_options_set_hint_style(o, CAIRO_HINT_STYLE_NONE);
    cairo_set_font_options(cr, o);
    cairo_font_options_destroy(o);
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  }
  ~CairoMeasure() {
    cairo_destroy(cr);
    cairo_surface_destroy(surface);
  }
  double width(const std::string& s, double px) {
    cairo_set_font_size(cr, px);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    return std::max(e.x_advance, e.x_bearing + e.width);
  }
  cairo_font_extents_t font(double px) {
    cairo_set_font_size(cr, px);
    cairo_font_extents_t fe;
    cairo_font_extents(cr, &fe);
    return fe;
  }
};

TEST(CardLayout, TheFontTableMeasuresAsCairoDoesUnhinted) {
  CairoMeasure cairo;
  const std::string texts[] = {"ID 7", "Composition in red, blue and yellow", "workbench collection, 2026",
                               "Caf\xc3\xa9 \xc3\x9f\xc3\xb8 \xce\xa9\xce\xbb \xd0\x96\xd0\xb8 "
                               "\xe2\x80\x94 \xe2\x80\xa6",
                               "fff jjj ///", "W", "iiiiiiiiiiiiiiiiiiii", "0123456789 +-*/=<>"};
  double worst = 0;
  for (double px : {7.5, 12.0, 18.0, 28.0, 32.0, 64.0, 200.0})
    for (const std::string& t : texts) {
      const double d = std::abs(card_text_width(t, px) - cairo.width(t, px));
      worst = std::max(worst, d / px);
      EXPECT_LT(d, 0.02 * px / 16 + 0.02) << '"' << t << "\" at " << px << " px: table " << card_text_width(t, px)
                                          << ", cairo " << cairo.width(t, px);
    }
  for (double px : {12.0, 28.0, 64.0}) {
    const cairo_font_extents_t fe = cairo.font(px);
    EXPECT_NEAR(card_font_ascent(px), fe.ascent, 0.02 * px / 16 + 0.02);
    EXPECT_NEAR(card_font_height(px), fe.height, 0.02 * px / 16 + 0.02);
  }
  std::printf("table and cairo differ by at most %.2g of the size\n", worst);
}

TEST(CardLayout, LinesAreCutToTheSideAndEndedWithAnEllipsis) {
  MediaSpec spec;
  spec.kind = MediaKind::text;
  spec.font_px = 64;
  spec.text = std::string(100000, 'W');
  const CardLayout wide = layout_text_card(spec);
  EXPECT_LE(wide.width, MediaStore::kMaxCardSide);
  EXPECT_GT(wide.width, MediaStore::kMaxCardSide - 64 * 2) << "a long line fills the side";
  ASSERT_EQ(wide.lines.size(), 1u);
  EXPECT_TRUE(wide.lines[0].ends_with("\u2026"));
  EXPECT_LE(card_text_width(wide.lines[0], 64), MediaStore::kMaxCardSide - 2 * wide.pad);
  spec.text = "a\tb\x01\nc";
  const CardLayout clean = layout_text_card(spec);
  ASSERT_EQ(clean.lines.size(), 2u);
  EXPECT_EQ(clean.lines[0], "a    b");
  EXPECT_EQ(clean.height, 2 * clean.line_h + 2 * clean.pad);
}

// The card MediaStore draws is the layout's size, and its text's pixels lie within the lines' boxes.
TEST(CardLayout, TheDrawnCardIsTheLayoutsSize) {
  MediaStore store(StoreMode::offline);
  MediaSpec spec;
  spec.kind = MediaKind::text;
  spec.font_px = 28;
  spec.text = "Composition in red, blue and yellow\nworkbench collection, 2026";
  spec.background = {0, 0, 0, 0};
  const CardLayout l = layout_text_card(spec);
  const auto card = store.text_card(spec);
  ASSERT_EQ(card->size(), cv::Size(l.width, l.height));
  const cv::Mat m = *card->current(nullptr);
  int inked = 0, right = 0;
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x)
      if (m.at<cv::Vec4b>(y, x)[3] > 0) ++inked, right = std::max(right, x);
  EXPECT_GT(inked, 500);
  EXPECT_LE(right, l.width - l.pad + 1) << "ink past the measured width";
  EXPECT_GE(right, l.width - l.pad - 4) << "the widest line ends where it was measured to end";
}

}  // namespace
}  // namespace arwb::media
