#include "dim2/xml_lite.hpp"

#include <cctype>
#include <cstdint>

#include "core/error.hpp"

namespace febemesh::dim2 {

const XmlAttribute* XmlElement::attribute(const std::string& n) const {
  for (const auto& a : attributes)
    if (a.name == n) return &a;
  return nullptr;
}

std::string XmlElement::local_name() const {
  auto colon = name.find(':');
  return colon == std::string::npos ? name : name.substr(colon + 1);
}

TextPos position_in_value(const XmlAttribute& a, std::size_t offset) {
  TextPos p = a.value_pos;
  for (std::size_t i = 0; i < offset && i < a.value.size(); ++i) {
    if (a.value[i] == '\n') {
      ++p.line;
      p.col = 1;
    } else {
      ++p.col;
    }
  }
  return p;
}

namespace {

bool is_name_start(unsigned char c) { return std::isalpha(c) || c == '_' || c == ':' || c >= 0x80; }
bool is_name_char(unsigned char c) {
  return is_name_start(c) || std::isdigit(c) || c == '-' || c == '.';
}
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

void append_utf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

class Parser {
 public:
  Parser(const std::string& text, const std::string& source) : s_(text), source_(source) {}

  XmlElement document() {
    if (s_.compare(0, 3, "\xEF\xBB\xBF") == 0) advance(3);  // UTF-8 byte order mark
    skip_misc(true);
    if (at_end()) fail("no root element (empty or not an XML document)");
    if (peek() != '<') fail("expected '<' to start the root element");
    XmlElement root = element();
    skip_misc(false);
    if (!at_end()) fail("content after the root element");
    return root;
  }

 private:
  const std::string& s_;
  const std::string& source_;
  std::size_t i_ = 0;
  TextPos pos_;

  bool at_end() const { return i_ >= s_.size(); }
  char peek(std::size_t k = 0) const { return i_ + k < s_.size() ? s_[i_ + k] : '\0'; }
  bool starts(const char* lit) const { return s_.compare(i_, std::char_traits<char>::length(lit), lit) == 0; }
  void advance(std::size_t n = 1) {
    for (std::size_t k = 0; k < n && i_ < s_.size(); ++k, ++i_) {
      if (s_[i_] == '\n') {
        ++pos_.line;
        pos_.col = 1;
      } else if ((static_cast<unsigned char>(s_[i_]) & 0xC0) != 0x80) {
        ++pos_.col;  // count characters, not UTF-8 continuation bytes
      }
    }
  }
  [[noreturn]] void fail(const std::string& why) const { fail_at(pos_, why); }
  [[noreturn]] void fail_at(TextPos p, const std::string& why) const {
    throw InputError(source_ + ":" + std::to_string(p.line) + ":" + std::to_string(p.col) + ": malformed XML: " + why);
  }
  void skip_space() {
    while (!at_end() && is_space(peek())) advance();
  }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected '") + c + "'" + (at_end() ? " but the file ends" : ""));
    advance();
  }
  void skip_until(const char* end_lit, const char* what) {
    TextPos start = pos_;
    while (!at_end() && !starts(end_lit)) advance();
    if (at_end()) fail_at(start, std::string("unterminated ") + what);
    advance(std::char_traits<char>::length(end_lit));
  }

  /// Comments, processing instructions, whitespace and (in the prolog) one DOCTYPE.
  void skip_misc(bool prolog) {
    for (;;) {
      skip_space();
      if (starts("<!--")) {
        skip_comment();
      } else if (starts("<?")) {
        skip_until("?>", "processing instruction");
      } else if (prolog && starts("<!DOCTYPE")) {
        skip_doctype();
      } else {
        return;
      }
    }
  }
  void skip_comment() {
    TextPos start = pos_;
    advance(4);
    while (!at_end() && !starts("--")) advance();
    if (at_end()) fail_at(start, "unterminated comment");
    if (!starts("-->")) fail("'--' inside a comment");
    advance(3);
  }
  void skip_doctype() {
    TextPos start = pos_;
    int depth = 0;
    char quote = 0;
    while (!at_end()) {
      char c = peek();
      advance();
      if (quote) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '[') {
        ++depth;
      } else if (c == ']') {
        --depth;
      } else if (c == '>' && depth <= 0) {
        return;
      }
    }
    fail_at(start, "unterminated DOCTYPE");
  }

  std::string name() {
    if (at_end() || !is_name_start(static_cast<unsigned char>(peek()))) fail("expected a name");
    std::size_t b = i_;
    while (!at_end() && is_name_char(static_cast<unsigned char>(peek()))) advance();
    return s_.substr(b, i_ - b);
  }

  void reference(std::string& out) {
    TextPos start = pos_;
    advance();  // '&'
    std::size_t b = i_;
    while (!at_end() && peek() != ';' && i_ - b < 12) advance();
    if (peek() != ';') fail_at(start, "unterminated character reference");
    std::string ref = s_.substr(b, i_ - b);
    advance();
    if (ref == "lt") out += '<';
    else if (ref == "gt") out += '>';
    else if (ref == "amp") out += '&';
    else if (ref == "quot") out += '"';
    else if (ref == "apos") out += '\'';
    else if (ref.size() > 1 && ref[0] == '#') {
      bool hex = ref[1] == 'x';
      std::string digits = ref.substr(hex ? 2 : 1);
      if (digits.empty()) fail_at(start, "empty numeric character reference");
      std::uint32_t cp = 0;
      for (char c : digits) {
        int d = std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
                : hex && std::isxdigit(static_cast<unsigned char>(c)) ? std::tolower(c) - 'a' + 10
                                                                       : -1;
        if (d < 0) fail_at(start, "bad numeric character reference '&" + ref + ";'");
        cp = cp * (hex ? 16 : 10) + static_cast<std::uint32_t>(d);
        if (cp > 0x10FFFF) fail_at(start, "character reference out of range");
      }
      if (cp == 0) fail_at(start, "character reference to NUL");
      append_utf8(out, cp);
    } else {
      fail_at(start, "unknown entity '&" + ref + ";'");
    }
  }

  XmlAttribute attribute() {
    XmlAttribute a;
    a.name = name();
    skip_space();
    expect('=');
    skip_space();
    char q = peek();
    if (q != '"' && q != '\'') fail("attribute value must be quoted");
    TextPos open = pos_;
    advance();
    a.value_pos = pos_;
    for (;;) {
      if (at_end()) fail_at(open, "unterminated attribute value");
      char c = peek();
      if (c == q) break;
      if (c == '<') fail("'<' inside an attribute value");
      if (c == '&') {
        reference(a.value);
      } else {
        a.value += c;
        advance();
      }
    }
    advance();
    return a;
  }

  XmlElement element() {
    XmlElement e;
    e.pos = pos_;
    expect('<');
    e.name = name();
    for (;;) {
      bool had_space = !at_end() && is_space(peek());
      skip_space();
      if (at_end()) fail_at(e.pos, "unterminated start tag <" + e.name + ">");
      if (peek() == '/' || peek() == '>') break;
      if (!had_space) fail("expected whitespace before an attribute");
      TextPos at = pos_;
      XmlAttribute a = attribute();
      if (e.attribute(a.name)) fail_at(at, "duplicate attribute '" + a.name + "'");
      e.attributes.push_back(std::move(a));
    }
    if (peek() == '/') {
      advance();
      expect('>');
      return e;
    }
    expect('>');
    content(e);
    return e;
  }

  void content(XmlElement& e) {
    for (;;) {
      if (at_end()) fail_at(e.pos, "element <" + e.name + "> is never closed");
      if (starts("</")) {
        TextPos at = pos_;
        advance(2);
        std::string n = name();
        if (n != e.name)
          fail_at(at, "closing tag </" + n + "> does not match <" + e.name + "> opened at line " +
                          std::to_string(e.pos.line) + ", column " + std::to_string(e.pos.col));
        skip_space();
        expect('>');
        return;
      }
      if (starts("<!--")) {
        skip_comment();
      } else if (starts("<![CDATA[")) {
        skip_until("]]>", "CDATA section");
      } else if (starts("<?")) {
        skip_until("?>", "processing instruction");
      } else if (starts("<!")) {
        fail("unexpected markup declaration");
      } else if (peek() == '<') {
        e.children.push_back(element());
      } else if (peek() == '&') {
        std::string ignored;
        reference(ignored);  // text is not used, but a broken reference is still malformed XML
      } else {
        advance();
      }
    }
  }
};

}  // namespace

XmlElement parse_xml(const std::string& text, const std::string& source) {
  return Parser(text, source).document();
}

}  // namespace febemesh::dim2
