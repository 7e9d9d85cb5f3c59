// pugixml parses; this file makes it strict. pugixml is lenient by design (unknown entities, a bare '&', duplicate
// attributes, several roots and control characters all load), so it runs without decoding entities and the tree
// is then checked here. Every problem is kept with its place in the text and the first one in document order is
// reported, so the message is the one a reader of the file meets first. pugixml gives byte offsets; lines are
// counted from them.
#include "script/xml_reader.hpp"

#include <pugixml.hpp>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <unordered_set>

namespace arwb::script {
namespace {

constexpr int kMaxDepth = 64;
constexpr const char* kNoDoctype = "DOCTYPE declarations are not allowed (no DTD, no external entities)";

bool valid_code_point(uint32_t c) {
  return c == 0x9 || c == 0xA || c == 0xD || (c >= 0x20 && c <= 0xD7FF) || (c >= 0xE000 && c <= 0xFFFD) ||
         (c >= 0x10000 && c <= 0x10FFFF);
}

void append_utf8(std::string& out, uint32_t c) {
  if (c < 0x80) {
    out += static_cast<char>(c);
  } else if (c < 0x800) {
    out += static_cast<char>(0xC0 | (c >> 6));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    out += static_cast<char>(0xE0 | (c >> 12));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (c >> 18));
    out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  }
}

std::string lower(std::string_view s) {
  std::string out;
  for (char c : s) out += static_cast<char>((c >= 'A' && c <= 'Z') ? c + 32 : c);
  return out;
}

bool only_space(std::string_view s) { return s.find_first_not_of(" \t\r\n") == std::string_view::npos; }

class Reader {
 public:
  explicit Reader(std::string_view text) : text_(text), buf_(text.begin(), text.end()) {
    // pugixml parsing a fragment in place overwrites the buffer's last character: give it one past the text.
    buf_.push_back('\n');
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') newlines_.push_back(i);
  }

  Result<XmlElement> read(std::string_view display) {
    for (size_t i = 0; i < text_.size(); ++i) {
      const auto c = static_cast<unsigned char>(text_[i]);
      if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') {
        problem(i, "control character " + std::to_string(c) + " in the file");
        break;
      }
    }
    // A fragment, so that text and elements after the root reach the checks below instead of being dropped.
    const unsigned flags = (pugi::parse_default | pugi::parse_declaration | pugi::parse_doctype |
                            pugi::parse_comments | pugi::parse_pi | pugi::parse_ws_pcdata | pugi::parse_fragment) &
                           ~(pugi::parse_escapes | pugi::parse_wconv_attribute);
    pugi::xml_document doc;
    const pugi::xml_parse_result r = doc.load_buffer_inplace(buf_.data(), buf_.size(), flags, pugi::encoding_utf8);
    const size_t bom = text_.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
    std::optional<XmlElement> root;
    for (const pugi::xml_node n : doc.children()) {
      const size_t at = offset(n, 0);
      switch (n.type()) {
        case pugi::node_declaration:
          if (at != bom + 2 || std::string_view(n.name()) != "xml")
            problem(at, "the XML declaration must be at the very start of the file");
          else declaration(n, at);
          break;
        case pugi::node_pcdata:
          if (!only_space(n.value()))
            problem(at + std::string_view(n.value()).find_first_not_of(" \t\r\n"), root ? "only one root element is allowed; found text after </" + root->name + ">"
                             : std::string("expected the root element"));
          break;
        case pugi::node_cdata: problem(at, "a CDATA section outside the root element"); break;
        case pugi::node_element:
          if (root) problem(at, "only one root element is allowed; found more after </" + root->name + ">");
          else root = element(n, 0);
          break;
        default: other(n, at);
      }
    }
    if (!r) parse_failure(doc, r);
    if (!root) problem(text_.size(), "no root element");
    if (first_)
      return fail(std::string(display) + ":" + std::to_string(first_->line) + ": " + first_->message);
    return std::move(*root);
  }

 private:
  struct Problem {
    size_t offset;
    int line;
    std::string message;
  };

  int line_at(size_t offset) const {
    return 1 + static_cast<int>(std::lower_bound(newlines_.begin(), newlines_.end(), offset) - newlines_.begin());
  }
  void problem(size_t offset, std::string message, int line = 0) {
    if (!first_ || offset < first_->offset) first_ = Problem{offset, line ? line : line_at(offset), std::move(message)};
  }
  // Where a name or value pugixml returns starts in the text; `fallback` when it is not in the buffer (pugixml
  // hands out a static empty string for what a failed parse left unset).
  size_t offset(const char* p, size_t fallback) const {
    const auto b = reinterpret_cast<uintptr_t>(buf_.data()), q = reinterpret_cast<uintptr_t>(p);
    return q >= b && q < b + buf_.size() ? q - b : fallback;
  }
  size_t offset(const pugi::xml_node& n, size_t fallback) const {
    const ptrdiff_t d = n.offset_debug();
    return d >= 0 ? static_cast<size_t>(d) : fallback;
  }

  // Comments, processing instructions and a DOCTYPE, wherever they are.
  void other(const pugi::xml_node& n, size_t at) {
    if (n.type() == pugi::node_doctype) {
      problem(at, kNoDoctype);
    } else if (n.type() == pugi::node_comment) {
      const std::string_view v = n.value();
      const size_t dash = v.find("--");
      if (dash != std::string_view::npos || (!v.empty() && v.back() == '-'))
        problem(at + std::min(dash, v.size() - 1), "'--' is not allowed inside a comment");
    } else if (n.type() == pugi::node_pi || n.type() == pugi::node_declaration) {
      if (lower(n.name()) == "xml") problem(at, "the XML declaration must be at the very start of the file");
    }
  }

  // <?xml version="1.0" encoding="UTF-8" standalone="yes"?>
  void declaration(const pugi::xml_node& n, size_t at) {
    bool version = false;
    for (const pugi::xml_attribute a : n.attributes()) {
      const std::string_view k = a.name(), v = a.value();
      const size_t where = offset(a.value(), at);
      if (k == "version") {
        version = true;
        if (v.substr(0, 2) != "1.") problem(where, "XML version '" + std::string(v) + "' is not supported");
      } else if (k == "encoding") {
        const std::string u = lower(v);
        if (u != "utf-8" && u != "utf8" && u != "us-ascii" && u != "ascii")
          problem(where, "encoding '" + std::string(v) + "' is not supported (UTF-8 only)");
      } else if (k != "standalone") {
        problem(offset(a.name(), at), "unexpected '" + std::string(k) + "' in the XML declaration");
      }
    }
    if (!version) problem(at, "the XML declaration needs a version");
  }

  XmlElement element(const pugi::xml_node& n, int depth) {
    XmlElement e;
    e.name = n.name();
    const size_t at = offset(n, 0);
    e.line = line_at(at);
    std::unordered_set<std::string_view> names;
    for (const pugi::xml_attribute a : n.attributes()) {
      if (!names.insert(a.name()).second)
        problem(offset(a.name(), at), "attribute '" + std::string(a.name()) + "' given twice in <" + e.name + ">");
      e.attributes.emplace_back(a.name(), decode(a.value(), offset(a.value(), at), true));
    }
    for (const pugi::xml_node c : n.children()) {
      const size_t cat = offset(c, at);
      switch (c.type()) {
        case pugi::node_pcdata: e.text += decode(c.value(), cat, false); break;
        case pugi::node_cdata: e.text += c.value(); break;
        case pugi::node_element:
          // pugixml parses without recursion; building the tree here recurses, so depth is capped.
          if (depth + 1 > kMaxDepth) problem(cat, "elements nested more than " + std::to_string(kMaxDepth) + " deep");
          else e.children.push_back(element(c, depth + 1));
          break;
        default: other(c, cat);
      }
    }
    return e;
  }

  // Character data or an attribute value as pugixml left it (line ends normalised, references not decoded):
  // references decoded, a bare '&' refused, and in attributes '<' refused and whitespace made spaces.
  std::string decode(std::string_view v, size_t at, bool attribute) {
    std::string out;
    int line = line_at(at);
    for (size_t i = 0; i < v.size();) {
      const char c = v[i];
      if (c == '&') {
        const size_t end = v.find(';', i);
        if (end == std::string_view::npos || end - i > 13)
          return problem(at + i, "'&' must start an entity such as &amp;", line), out;
        const std::string ref(v.substr(i + 1, end - i - 1));
        if (std::string why = reference(ref, out); !why.empty()) return problem(at + i, why, line), out;
        i = end + 1;
        continue;
      }
      if (attribute && c == '<') return problem(at + i, "'<' is not allowed in an attribute value", line), out;
      if (!attribute && v.substr(i, 3) == "]]>") return problem(at + i, "']]>' is not allowed in text", line), out;
      if (c == '\n') ++line;
      out += attribute && (c == '\t' || c == '\n' || c == '\r') ? ' ' : c;   // attribute-value normalisation
      ++i;
    }
    return out;
  }

  // &ref; decoded onto out, or why not.
  static std::string reference(const std::string& ref, std::string& out) {
    if (ref == "lt") out += '<';
    else if (ref == "gt") out += '>';
    else if (ref == "amp") out += '&';
    else if (ref == "apos") out += '\'';
    else if (ref == "quot") out += '"';
    else if (ref.size() >= 2 && ref[0] == '#') {
      const bool hex = ref[1] == 'x';
      const std::string digits = ref.substr(hex ? 2 : 1);
      if (digits.empty()) return "empty character reference &" + ref + ";";
      uint32_t c = 0;
      for (char d : digits) {
        int v = -1;
        if (d >= '0' && d <= '9') v = d - '0';
        else if (hex && d >= 'a' && d <= 'f') v = d - 'a' + 10;
        else if (hex && d >= 'A' && d <= 'F') v = d - 'A' + 10;
        if (v < 0) return "bad character reference &" + ref + ";";
        c = c * (hex ? 16u : 10u) + static_cast<uint32_t>(v);
        if (c > 0x10FFFF) break;
      }
      if (!valid_code_point(c)) return "character reference &" + ref + "; is not a valid XML character";
      append_utf8(out, c);
    } else {
      return "unknown entity &" + ref +
             "; (only &lt; &gt; &amp; &apos; &quot; and numeric references; there is no DTD)";
    }
    return "";
  }

  void parse_failure(const pugi::xml_document& doc, const pugi::xml_parse_result& r) {
    const size_t at = std::min(static_cast<size_t>(std::max<ptrdiff_t>(r.offset, 0)), text_.size());
    if (first_ && first_->offset <= at) return;   // an earlier problem is the one to report
    switch (r.status) {
      case pugi::status_end_element_mismatch: return mismatch(doc, at);
      case pugi::status_bad_attribute:
        return problem(at, "expected name=\"value\" (quoted, after whitespace) or the end of the tag");
      case pugi::status_bad_doctype: return problem(at, kNoDoctype);
      case pugi::status_unrecognized_tag: {
        const size_t lt = text_.rfind('<', at);
        if (lt != std::string_view::npos && lower(text_.substr(lt, 9)) == "<!doctype") return problem(lt, kNoDoctype);
        return problem(at, "unexpected markup (a '<' must start a tag, a comment or a CDATA section)");
      }
      case pugi::status_bad_pi:
        return problem(at, "bad processing instruction (the XML declaration must be at the very start of the file)");
      case pugi::status_bad_comment: return problem(at, "unterminated comment");
      case pugi::status_bad_cdata: return problem(at, "unterminated CDATA section");
      case pugi::status_bad_start_element: return problem(at, "bad start tag");
      case pugi::status_bad_end_element: return problem(at, "bad end tag");
      case pugi::status_out_of_memory: return problem(at, "not enough memory to read the file");
      default: return problem(at, lower(r.description()));
    }
  }

  // pugixml says an end tag does not match (at its name) or the text ended with elements open. The element left
  // open is found on the partial tree's last branch: the deepest one with fewer end tags in the text since its
  // start than elements of its name inside it. Nesting is capped above, so the branch is short.
  void mismatch(const pugi::xml_document& doc, size_t at) {
    const bool end_tag = at >= 2 && text_.substr(at - 2, 2) == "</";
    const size_t until = end_tag ? at - 2 : text_.size();
    std::vector<pugi::xml_node> branch;
    for (pugi::xml_node n = doc.last_child(); n && branch.size() <= kMaxDepth + 1; n = n.last_child()) {
      while (n && n.type() != pugi::node_element) n = n.previous_sibling();
      if (!n) break;
      branch.push_back(n);
    }
    const pugi::xml_node* open = nullptr;
    for (auto it = branch.rbegin(); it != branch.rend() && !open; ++it) {
      const std::string_view name = it->name();
      const size_t from = std::min(offset(*it, until), until);
      size_t ends = 0;
      for (size_t p = text_.find("</", from); p < until; p = text_.find("</", p + 2))
        if (text_.substr(p + 2, name.size()) == name && p + 2 + name.size() < text_.size() &&
            std::string_view(" \t\r\n>").find(text_[p + 2 + name.size()]) != std::string_view::npos)
          ++ends;
      if (ends < named_in(*it, name)) open = &*it;
    }
    // Appended, not "<" + name: g++ 12 warns falsely (-Wrestrict) on literal + string.
    std::string tag = "<";
    if (open) tag.append(open->name()).append(">");
    const std::string line = open ? std::to_string(line_at(offset(*open, 0))) : "";
    if (!end_tag) {
      problem(at, open ? tag.append(" (line ").append(line).append(") is never closed") : "an element is never closed");
      return;
    }
    size_t e = at;
    while (e < text_.size() && e - at < 40 && std::string_view(" \t\r\n>").find(text_[e]) == std::string_view::npos)
      ++e;
    std::string message = "</";
    message.append(text_.substr(at, e - at)).append("> closes ");
    message.append(open ? tag.append(" opened on line ").append(line) : "no open element");
    problem(at, message);
  }

  // Elements named `name` in the subtree at top (top included), without recursion.
  static size_t named_in(const pugi::xml_node& top, std::string_view name) {
    size_t n = 0;
    for (pugi::xml_node x = top; x;) {
      if (x.type() == pugi::node_element && name == x.name()) ++n;
      if (x.first_child()) {
        x = x.first_child();
        continue;
      }
      while (x != top && !x.next_sibling()) x = x.parent();
      if (x == top) break;
      x = x.next_sibling();
    }
    return n;
  }

  std::string_view text_;
  std::vector<char> buf_;
  std::vector<size_t> newlines_;
  std::optional<Problem> first_;
};

}  // namespace

const std::string* XmlElement::attribute(std::string_view n) const {
  for (const auto& [k, v] : attributes)
    if (k == n) return &v;
  return nullptr;
}

Result<XmlElement> parse_xml(std::string_view text, std::string_view display) {
  try {
    return Reader(text).read(display);
  } catch (const std::bad_alloc&) {
    return fail(std::string(display) + ": not enough memory to read the file");
  }
}

}  // namespace arwb::script
