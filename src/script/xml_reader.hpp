// The paper's database files through pugixml, made strict: elements, attributes, character data, comments, CDATA
// sections, processing instructions (skipped), the XML declaration, the five predefined entities and numeric
// character references. No DTD: a <!DOCTYPE> is refused, so no entity can be declared or fetched. UTF-8 only.
// Every element keeps the line it starts on, for messages.
#pragma once

#include "base/result.hpp"

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace arwb::script {

struct XmlElement {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;   // in document order, values decoded
  std::vector<XmlElement> children;
  std::string text;   // the element's own character data (not its children's), decoded and concatenated
  int line = 0;

  const std::string* attribute(std::string_view name) const;
};

// The document's root element, or the first problem in document order as "DISPLAY:LINE: message".
Result<XmlElement> parse_xml(std::string_view text, std::string_view display);

}  // namespace arwb::script
