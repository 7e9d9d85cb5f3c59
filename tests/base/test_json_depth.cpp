// check_json_depth: the levels of arrays and objects, strings and their escapes skipped, the line of the first
// level past the limit.
#include "base/json_depth.hpp"

#include <gtest/gtest.h>

#include <string>

namespace arwb {
namespace {

TEST(JsonDepth, OrdinaryJsonAndBracketsInStringsPass) {
  EXPECT_TRUE(check_json_depth(R"({"a": [1, {"b": [2, 3]}], "c": "[[[[{{{{"})", "f.json"));
  EXPECT_TRUE(check_json_depth(R"({"quote": "\"[[[[", "backslash": "\\", "after": [1]})", "f.json"));
  EXPECT_TRUE(check_json_depth("", "f.json"));
  EXPECT_TRUE(check_json_depth("]]]]}}}} [1]", "f.json")) << "closers without openers are the parser's to report";
  EXPECT_TRUE(check_json_depth(std::string(64, '[') + std::string(64, ']'), "f.json"));
}

TEST(JsonDepth, DeepNestingIsRefusedAtItsLine) {
  EXPECT_EQ(check_json_depth(std::string(65, '['), "f.json").error(), "f.json:1: nested deeper than 64 levels");
  EXPECT_EQ(check_json_depth("{\n\"a\":\n" + std::string(40000, '{'), "m.gltf").error(),
            "m.gltf:3: nested deeper than 64 levels");
  EXPECT_EQ(check_json_depth("[[[[", "f.json", 3).error(), "f.json:1: nested deeper than 3 levels");
  EXPECT_EQ(check_json_depth("\n[[[[", "", 3).error(), "line 2: nested deeper than 3 levels");
  // Levels closed come back: many shallow arrays in a row are fine.
  std::string wide;
  for (int i = 0; i < 1000; ++i) wide += "[[[]]],";
  EXPECT_TRUE(check_json_depth("[" + wide + "1]", "f.json"));
  // An escaped quote does not end the string: the brackets after it are still text.
  EXPECT_TRUE(check_json_depth("\"\\\"" + std::string(100, '[') + "\"", "f.json"));
}

}  // namespace
}  // namespace arwb
