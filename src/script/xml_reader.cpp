#include "script/xml_reader.hpp"

#include <cstdint>

namespace arwb::script {
namespace {

constexpr int kMaxDepth = 64;

struct Fail {
  int line;
  std::string message;
};

bool is_name_start(unsigned char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_' || c == ':' || c >= 0x80;
}
bool is_name_char(unsigned char c) {
  return is_name_start(c) || (c >= '0' && c <= '9') || c == '-' || c == '.';
}
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

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

class Parser {
 public:
  explicit Parser(std::string_view s) : s_(s) {}

  XmlElement document() {
    if (starts("\xEF\xBB\xBF")) i_ += 3;
    if (starts("<?xml") && i_ + 5 < s_.size() && is_space(s_[i_ + 5])) declaration();
    misc();
    if (at_end()) fail("no root element");
    if (!starts("<") || i_ + 1 >= s_.size() || !is_name_start(static_cast<unsigned char>(s_[i_ + 1])))
      fail("expected the root element");
    XmlElement root = element(0);
    misc();
    if (!at_end()) fail("only one root element is allowed; found more after </" + root.name + ">");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& message) { throw Fail{line_, message}; }
  bool at_end() const { return i_ >= s_.size(); }
  bool starts(std::string_view p) const { return s_.substr(i_, p.size()) == p; }
  char peek() const { return at_end() ? '\0' : s_[i_]; }

  // Moves over n characters, counting lines and refusing control characters.
  void advance(size_t n = 1) {
    for (size_t k = 0; k < n && i_ < s_.size(); ++k, ++i_) {
      const unsigned char c = static_cast<unsigned char>(s_[i_]);
      if (c == '\n') ++line_;
      else if (c < 0x20 && c != '\t' && c != '\r') fail("control character " + std::to_string(c) + " in the file");
    }
  }
  void skip_space() {
    while (!at_end() && is_space(peek())) advance();
  }
  void expect(std::string_view p, const char* what) {
    if (!starts(p)) fail(std::string("expected ") + what);
    advance(p.size());
  }

  std::string name() {
    if (at_end() || !is_name_start(static_cast<unsigned char>(peek()))) fail("expected a name");
    const size_t start = i_;
    while (!at_end() && is_name_char(static_cast<unsigned char>(peek()))) advance();
    return std::string(s_.substr(start, i_ - start));
  }

  // &...; at the current position, decoded onto out.
  void reference(std::string& out) {
    const int line = line_;
    advance();   // '&'
    const size_t end = s_.find(';', i_);
    if (end == std::string_view::npos || end - i_ > 12) throw Fail{line, "'&' must start an entity such as &amp;"};
    const std::string_view ref = s_.substr(i_, end - i_);
    advance(ref.size() + 1);
    if (ref == "lt") out += '<';
    else if (ref == "gt") out += '>';
    else if (ref == "amp") out += '&';
    else if (ref == "apos") out += '\'';
    else if (ref == "quot") out += '"';
    else if (ref.size() >= 2 && ref[0] == '#') {
      const bool hex = ref[1] == 'x';
      const std::string_view digits = ref.substr(hex ? 2 : 1);
      if (digits.empty()) throw Fail{line, "empty character reference &" + std::string(ref) + ";"};
      uint32_t c = 0;
      for (char d : digits) {
        int v = -1;
        if (d >= '0' && d <= '9') v = d - '0';
        else if (hex && d >= 'a' && d <= 'f') v = d - 'a' + 10;
        else if (hex && d >= 'A' && d <= 'F') v = d - 'A' + 10;
        if (v < 0) throw Fail{line, "bad character reference &" + std::string(ref) + ";"};
        c = c * (hex ? 16u : 10u) + static_cast<uint32_t>(v);
        if (c > 0x10FFFF) break;
      }
      if (!valid_code_point(c)) throw Fail{line, "character reference &" + std::string(ref) + "; is not a valid XML character"};
      append_utf8(out, c);
    } else {
      throw Fail{line, "unknown entity &" + std::string(ref) +
                           "; (only &lt; &gt; &amp; &apos; &quot; and numeric references; there is no DTD)"};
    }
  }

  std::string attribute_value() {
    const char q = peek();
    if (q != '"' && q != '\'') fail("expected a quoted attribute value");
    advance();
    std::string v;
    while (true) {
      if (at_end()) fail("unterminated attribute value");
      const char c = peek();
      if (c == q) break;
      if (c == '<') fail("'<' is not allowed in an attribute value");
      if (c == '&') {
        reference(v);
        continue;
      }
      v += (c == '\t' || c == '\n' || c == '\r') ? ' ' : c;   // attribute-value normalisation
      advance();
    }
    advance();
    return v;
  }

  // <?xml version="1.0" encoding="UTF-8" standalone="yes"?>
  void declaration() {
    advance(5);
    bool version = false;
    while (true) {
      skip_space();
      if (starts("?>")) {
        advance(2);
        break;
      }
      if (at_end()) fail("unterminated XML declaration");
      const std::string n = name();
      skip_space();
      expect("=", "'=' in the XML declaration");
      skip_space();
      const std::string v = attribute_value();
      if (n == "version") {
        version = true;
        if (v.rfind("1.", 0) != 0) fail("XML version '" + v + "' is not supported");
      } else if (n == "encoding") {
        std::string u;
        for (char c : v) u += static_cast<char>((c >= 'a' && c <= 'z') ? c - 32 : c);
        if (u != "UTF-8" && u != "UTF8" && u != "US-ASCII" && u != "ASCII")
          fail("encoding '" + v + "' is not supported (UTF-8 only)");
      } else if (n != "standalone") {
        fail("unexpected '" + n + "' in the XML declaration");
      }
    }
    if (!version) fail("the XML declaration needs a version");
  }

  void comment() {
    advance(4);   // <!--
    const size_t end = s_.find("--", i_);
    if (end == std::string_view::npos) fail("unterminated comment");
    advance(end - i_);
    if (!starts("-->")) fail("'--' is not allowed inside a comment");
    advance(3);
  }

  void processing_instruction() {
    advance(2);   // <?
    const std::string target = name();
    std::string lower;
    for (char c : target) lower += static_cast<char>((c >= 'A' && c <= 'Z') ? c + 32 : c);
    if (lower == "xml") fail("the XML declaration must be at the very start of the file");
    const size_t end = s_.find("?>", i_);
    if (end == std::string_view::npos) fail("unterminated processing instruction");
    advance(end - i_ + 2);
  }

  // Whitespace, comments and processing instructions between the declaration, the root and the end.
  void misc() {
    while (true) {
      skip_space();
      if (starts("<!--")) comment();
      else if (starts("<?")) processing_instruction();
      else if (starts("<!DOCTYPE") || starts("<!doctype"))
        fail("DOCTYPE declarations are not allowed (no DTD, no external entities)");
      else if (starts("<!")) fail("unexpected '<!' markup");
      else return;
    }
  }

  XmlElement element(int depth) {
    if (depth > kMaxDepth) fail("elements nested more than " + std::to_string(kMaxDepth) + " deep");
    XmlElement e;
    e.line = line_;
    advance();   // '<'
    e.name = name();
    // attributes
    while (true) {
      const bool spaced = !at_end() && is_space(peek());
      skip_space();
      if (starts("/>")) {
        advance(2);
        return e;
      }
      if (starts(">")) {
        advance();
        break;
      }
      if (at_end()) fail("unterminated start tag <" + e.name + ">");
      if (!spaced) fail("expected whitespace before an attribute in <" + e.name + ">");
      const std::string n = name();
      skip_space();
      expect("=", ("'=' after attribute '" + n + "'").c_str());
      skip_space();
      std::string v = attribute_value();
      for (const auto& [k, _] : e.attributes)
        if (k == n) fail("attribute '" + n + "' given twice in <" + e.name + ">");
      e.attributes.emplace_back(n, std::move(v));
    }
    // content
    while (true) {
      if (at_end()) fail("<" + e.name + "> (line " + std::to_string(e.line) + ") is never closed");
      const char c = peek();
      if (c == '&') {
        reference(e.text);
      } else if (c != '<') {
        if (starts("]]>")) fail("']]>' is not allowed in text");
        e.text += c == '\r' ? '\n' : c;
        if (c == '\r' && i_ + 1 < s_.size() && s_[i_ + 1] == '\n') advance();
        advance();
      } else if (starts("</")) {
        advance(2);
        const std::string n = name();
        if (n != e.name)
          fail("</" + n + "> closes <" + e.name + "> opened on line " + std::to_string(e.line));
        skip_space();
        expect(">", "'>'");
        return e;
      } else if (starts("<!--")) {
        comment();
      } else if (starts("<![CDATA[")) {
        advance(9);
        const size_t end = s_.find("]]>", i_);
        if (end == std::string_view::npos) fail("unterminated CDATA section");
        const size_t start = i_;
        advance(end - i_);
        e.text += s_.substr(start, end - start);
        advance(3);
      } else if (starts("<?")) {
        processing_instruction();
      } else if (starts("<!DOCTYPE") || starts("<!doctype")) {
        fail("DOCTYPE declarations are not allowed (no DTD, no external entities)");
      } else if (starts("<!")) {
        fail("unexpected '<!' markup");
      } else {
        e.children.push_back(element(depth + 1));
      }
    }
  }

  std::string_view s_;
  size_t i_ = 0;
  int line_ = 1;
};

}  // namespace

const std::string* XmlElement::attribute(std::string_view n) const {
  for (const auto& [k, v] : attributes)
    if (k == n) return &v;
  return nullptr;
}

std::optional<XmlElement> parse_xml(std::string_view text, XmlError* error) {
  try {
    return Parser(text).document();
  } catch (const Fail& f) {
    if (error) *error = {f.line, f.message};
    return std::nullopt;
  }
}

}  // namespace arwb::script
