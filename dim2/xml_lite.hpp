#pragma once
// A small strict XML reader for SVG input: elements, attributes (with the predefined and numeric
// character references), comments, CDATA, processing instructions and a DOCTYPE are understood;
// anything malformed is refused with the line and column, since a silently half-read drawing
// would mesh the wrong solid. Text content is kept only as far as SVG needs it (not at all).

#include <string>
#include <utility>
#include <vector>

namespace febemesh::dim2 {

/// A place in the source text, 1-based.
struct TextPos {
  int line = 1;
  int col = 1;
};

struct XmlAttribute {
  std::string name;
  std::string value;  ///< entities decoded; raw newlines kept so positions inside can be found
  TextPos value_pos;  ///< first character of the value (after the quote)
};

struct XmlElement {
  std::string name;  ///< qualified name as written, e.g. "svg" or "svg:path"
  std::vector<XmlAttribute> attributes;
  std::vector<XmlElement> children;
  TextPos pos;  ///< the '<' of the start tag

  /// The attribute `name`, or nullptr.
  const XmlAttribute* attribute(const std::string& name) const;
  /// Local part of the name ("path" for "svg:path").
  std::string local_name() const;
};

/// Parses a whole document and returns its root element. Throws InputError
/// "SOURCE:LINE:COL: reason" on malformed XML.
XmlElement parse_xml(const std::string& text, const std::string& source);

/// Position of byte `offset` of an attribute value, assuming no character references precede it
/// (good enough to point into path data).
TextPos position_in_value(const XmlAttribute& a, std::size_t offset);

}  // namespace febemesh::dim2
