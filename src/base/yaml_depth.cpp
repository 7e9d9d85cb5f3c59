#include "base/yaml_depth.hpp"

#include <vector>

namespace arwb {

Status check_yaml_depth(std::string_view text, const std::string& name, int max_depth) {
  std::vector<size_t> block;  // the indentation column of each open block level, innermost last
  int flow = 0;               // open [ and { levels
  int line = 0;
  const auto too_deep = [&] {
    return fail(name + ":" + std::to_string(line) + ": nested deeper than " + std::to_string(max_depth) + " levels");
  };
  const auto depth = [&] { return static_cast<long long>(block.size()) + flow; };
  size_t start = 0;
  while (start < text.size() || (start == text.size() && line == 0)) {
    size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view l = text.substr(start, end - start);
    start = end + 1;
    ++line;
    size_t pos = 0;
    // Where a node may start: a flow collection opens there (elsewhere outside flow, "[" is part of a plain word).
    bool node_start = true;
    if (flow == 0) {
      while (pos < l.size() && (l[pos] == ' ' || l[pos] == '\t')) ++pos;
      if (pos == l.size() || l[pos] == '#' || l[pos] == '\r') continue;  // blank, or a comment only
      if (pos == 0 && (l[0] == '%' || l.substr(0, 3) == "---" || l.substr(0, 3) == "...")) {
        if (l[0] == '%') continue;  // a directive
        block.clear();              // a document starts or ends
        pos = 3;
        while (pos < l.size() && l[pos] == ' ') ++pos;
        if (pos >= l.size()) continue;
      } else {
        while (!block.empty() && block.back() > pos) block.pop_back();
        if (block.empty() || block.back() < pos) block.push_back(pos);
      }
      // "- - - x": each entry marker on the line starts a node one level deeper.
      while (pos < l.size() && (l[pos] == '-' || l[pos] == '?') && (pos + 1 == l.size() || l[pos + 1] == ' ')) {
        ++pos;
        while (pos < l.size() && l[pos] == ' ') ++pos;
        if (pos < l.size() && l[pos] != '#' && l[pos] != '\r') block.push_back(pos);
      }
      if (depth() > max_depth) return too_deep();
    }
    for (; pos < l.size(); ++pos) {
      const char c = l[pos];
      if (c == '#' && (pos == 0 || l[pos - 1] == ' ' || l[pos - 1] == '\t')) break;  // a comment
      if (c == '"' || c == '\'') {  // a quoted scalar: brackets in it are text (kept to its line, as OpenCV does)
        for (++pos; pos < l.size() && l[pos] != c; ++pos)
          if (c == '"' && l[pos] == '\\') ++pos;
        node_start = false;
        continue;
      }
      if ((c == '[' || c == '{') && (flow > 0 || node_start)) {
        ++flow;
        if (depth() > max_depth) return too_deep();
        node_start = true;
        continue;
      }
      if ((c == ']' || c == '}') && flow > 0) {
        --flow;
        continue;
      }
      if (c == ' ' || c == '\t') continue;
      // After "key:" or "," (in flow) a value may start; anywhere else we are inside a word.
      node_start = (c == ':' || (c == ',' && flow > 0));
    }
  }
  return {};
}

}  // namespace arwb
