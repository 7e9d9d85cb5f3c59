#include "base/json_depth.hpp"

namespace arwb {

Status check_json_depth(std::string_view text, const std::string& name, int max_depth) {
  int depth = 0;
  long line = 1;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (in_string) {
      if (c == '\\') ++i;   // the escaped character, a quote among them, is text (an escaped newline is not JSON)
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') in_string = true;
    else if (c == '[' || c == '{') {
      if (++depth > max_depth)
        return fail((name.empty() ? "line " : name + ":") + std::to_string(line) + ": nested deeper than " +
                    std::to_string(max_depth) + " levels");
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return {};
}

}  // namespace arwb
