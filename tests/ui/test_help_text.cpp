// The Help menu's words name the window's own controls: each 'quoted' name in the shortcuts and the "First five
// minutes" pages is a panel's title or the label of a control in ui/ (a string literal "NAME" or "NAME##...").
#include "ui/help_text.hpp"
#include "ui/panel_id.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

namespace arwb::ui {
namespace {

// The names in 'quotes': a quote opens at the start or after a space or '(', and closes before a non-letter (so
// "stage's" is not a quote).
std::vector<std::string> quoted(const std::string& text) {
  std::vector<std::string> out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\'' || (i > 0 && text[i - 1] != ' ' && text[i - 1] != '(')) continue;
    size_t j = i + 1;
    while (j < text.size() && !(text[j] == '\'' && (j + 1 == text.size() || !std::isalpha((unsigned char)text[j + 1]))))
      ++j;
    if (j < text.size()) out.push_back(text.substr(i + 1, j - i - 1));
    i = j;
  }
  return out;
}

TEST(HelpText, EveryQuotedNameIsAPanelOrAControlOfTheWindow) {
  std::string sources;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(ARWB_SOURCE_DIR) / "ui"))
    if (e.path().extension() == ".cpp" && e.path().filename() != "help_text.cpp") sources += test::read_file(e.path().string());
  std::vector<std::string> names;
  for (const Shortcut& s : shortcuts())
    for (const std::string& n : quoted(s.what)) names.push_back(n);
  for (const FirstStepsPage& p : first_steps_pages())
    for (const char* line : p.lines)
      for (const std::string& n : quoted(line)) names.push_back(n);
  // The names the issue found wrong ("the region tool", "Sweep") are there under the window's names.
  for (const char* must : {"Why? (drag)", "Find the smallest change that detects it", "Why not detected?"})
    EXPECT_NE(std::find(names.begin(), names.end(), must), names.end()) << must;
  for (const std::string& n : names) {
    bool panel = false;
    for (int i = 0; i < kPanelCount; ++i) panel = panel || n == panel_title(static_cast<Panel>(i));
    const bool control = sources.find('"' + n + '"') != std::string::npos || sources.find('"' + n + "##") != std::string::npos;
    EXPECT_TRUE(panel || control) << "'" << n << "' is neither a panel's title nor a control's label in ui/";
  }
  EXPECT_EQ(quoted("a 'B c' d's 'E'."), (std::vector<std::string>{"B c", "E"}));
}

}  // namespace
}  // namespace arwb::ui
