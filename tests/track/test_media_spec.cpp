// MediaSpec::describe for texts, as the Scene panel, the export's self-test and its README show them: a fixed
// text in quotes, a computed one marked so, without the empty quotes it has before it first runs.
#include "track/media_spec.hpp"

#include <gtest/gtest.h>

namespace arwb {
namespace {

TEST(MediaSpecDescribe, FixedAndComputedTexts) {
  MediaSpec m;
  m.kind = MediaKind::text;
  m.source = "hello";
  m.text = "hello";
  EXPECT_EQ(m.describe(), "text \"hello\"");
  m.source = "function";
  m.text = "";
  EXPECT_EQ(m.describe(), "text (computed)");
  m.text = "12:03";
  EXPECT_EQ(m.describe(), "text \"12:03\" (computed)");
}

}  // namespace
}  // namespace arwb
