// read_text_file: the whole text or one message naming the file; edit_distance and nearest_name for "did you
// mean ...?".
#include "base/files.hpp"
#include "base/text.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

namespace arwb {
namespace {

TEST(ReadTextFile, ReadsTheWholeFileAsItIs) {
  test::TempDir dir;
  const std::string text = std::string("line 1\r\nline 2\n\xEF\xBB\xBF", 18) + std::string(200000, 'x');
  test::write_file(dir.str("a.txt"), text);
  const Result<std::string> r = read_text_file(dir.str("a.txt"), 1u << 20);
  ASSERT_TRUE(r) << r.error();
  EXPECT_EQ(*r, text);
  test::write_file(dir.str("empty.txt"), "");
  EXPECT_EQ(*read_text_file(dir.str("empty.txt"), 10), "");
}

TEST(ReadTextFile, EachFailureNamesTheFile) {
  test::TempDir dir;
  EXPECT_EQ(read_text_file(dir.str("missing.txt"), 100).error(), dir.str("missing.txt") + ": no such file");
  EXPECT_EQ(read_text_file(dir.str(), 100).error(), dir.str() + ": not a regular file");
  EXPECT_EQ(read_text_file("/dev/null", 100).error(), "/dev/null: not a regular file");
  test::write_file(dir.str("big.txt"), std::string(2049, 'x'));
  EXPECT_EQ(read_text_file(dir.str("big.txt"), 2048).error(), dir.str("big.txt") + ": larger than 2 KiB");
  EXPECT_EQ(read_text_file(dir.str("big.txt"), 16u << 20).value().size(), 2049u);
  EXPECT_EQ(read_text_file(dir.str("big.txt"), 1000).error(), dir.str("big.txt") + ": larger than 1000 bytes");
}

TEST(EditDistance, CountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(edit_distance("", ""), 0);
  EXPECT_EQ(edit_distance("abc", ""), 3);
  EXPECT_EQ(edit_distance("", "abc"), 3);
  EXPECT_EQ(edit_distance("place", "place"), 0);
  EXPECT_EQ(edit_distance("plac", "place"), 1);
  EXPECT_EQ(edit_distance("pIace", "place"), 1);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3);
  EXPECT_EQ(edit_distance("otsu", "outs"), 2);
}

TEST(NearestName, OnlyATypoAway) {
  const std::vector<std::string> stages = {"otsu", "bit_grid", "contours"};
  EXPECT_EQ(nearest_name("otus", stages), "otsu");
  EXPECT_EQ(nearest_name("bitgrid", stages), "bit_grid");
  EXPECT_EQ(nearest_name("threshold", stages), "");
  const std::vector<std::string_view> fields = {"side", "place", "id"};
  EXPECT_EQ(nearest_name("sid", fields), "side");
  EXPECT_EQ(nearest_name("x", fields), "") << "a whole word replaced is no typo";
  EXPECT_EQ(nearest_name("side", fields), "side");
}

}  // namespace
}  // namespace arwb
