// PLY header parsing; see ply_header.h.
#include "mesh/ply_header.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "mesh/text_scan.h"

namespace dispex::mesh {
namespace {

struct TypeInfo {
  const char* name;
  const char* alias;
  Type type;
  int size;
};

constexpr TypeInfo kTypes[] = {
    {"char", "int8", Type::kInt8, 1},        {"uchar", "uint8", Type::kUint8, 1},
    {"short", "int16", Type::kInt16, 2},     {"ushort", "uint16", Type::kUint16, 2},
    {"int", "int32", Type::kInt32, 4},       {"uint", "uint32", Type::kUint32, 4},
    {"float", "float32", Type::kFloat32, 4}, {"double", "float64", Type::kFloat64, 8},
};

bool LookUpType(std::string_view name, Type& type) {
  for (const TypeInfo& info : kTypes) {
    if (name == info.name || name == info.alias) {
      type = info.type;
      return true;
    }
  }
  return false;
}

std::vector<std::string_view> SplitBlanks(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsBlank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !IsBlank(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

std::string Shown(std::string_view token) {
  return TokenForMessage(token.data(), token.data() + token.size(), 32);
}

// Element and property names end up in error messages: a control byte in one (binary bytes
// in a damaged header) would break the message's single line.
bool HasControlByte(std::string_view token) {
  return std::any_of(token.begin(), token.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return byte < 0x20 || byte == 0x7f;
  });
}

bool ParseCount(std::string_view token, std::uint64_t& count) {
  if (token.empty() || token.size() > 19) return false;
  std::uint64_t value = 0;
  for (char c : token) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + static_cast<unsigned>(c - '0');
  }
  count = value;
  return true;
}

// Each Parse*Line below returns the message of the line's error, empty when the line is fine.

std::string ParseFormatLine(const std::vector<std::string_view>& tokens, bool& have_format,
                            Header& header) {
  if (have_format) return "second 'format' line";
  if (tokens.size() != 3) return "format line needs a format and a version";
  if (tokens[1] == "ascii") {
    header.format = Format::kAscii;
  } else if (tokens[1] == "binary_little_endian") {
    header.format = Format::kBinaryLittleEndian;
  } else if (tokens[1] == "binary_big_endian") {
    header.format = Format::kBinaryBigEndian;
  } else {
    return fmt::format(
        "unknown format '{}' (ascii, binary_little_endian or "
        "binary_big_endian)",
        Shown(tokens[1]));
  }
  if (tokens[2] != "1.0" && tokens[2] != "1") {
    return fmt::format("unsupported PLY version '{}' (1.0 expected)", Shown(tokens[2]));
  }
  have_format = true;
  return {};
}

std::string ParseElementLine(const std::vector<std::string_view>& tokens, Header& header) {
  if (tokens.size() != 3) return "element line needs a name and a count";
  if (HasControlByte(tokens[1])) {
    return fmt::format("element name '{}' has a control character", Shown(tokens[1]));
  }
  Element element;
  element.name = std::string(tokens[1]);
  if (!ParseCount(tokens[2], element.count)) {
    return fmt::format("bad element count '{}'", Shown(tokens[2]));
  }
  header.elements.push_back(std::move(element));
  return {};
}

std::string ParsePropertyLine(const std::vector<std::string_view>& tokens, Header& header) {
  if (header.elements.empty()) return "property line before any element line";
  Property property;
  if (tokens.size() >= 2 && tokens[1] == "list") {
    if (tokens.size() != 5) return "list property needs a count type, an item type and a name";
    property.is_list = true;
    if (!LookUpType(tokens[2], property.count_type)) {
      return fmt::format("unsupported property type '{}'", Shown(tokens[2]));
    }
    if (!IsInteger(property.count_type)) {
      return fmt::format("list count type '{}' is not an integer type", Shown(tokens[2]));
    }
    if (!LookUpType(tokens[3], property.type)) {
      return fmt::format("unsupported property type '{}'", Shown(tokens[3]));
    }
    property.name = std::string(tokens[4]);
  } else {
    if (tokens.size() != 3) return "property line needs a type and a name";
    if (!LookUpType(tokens[1], property.type)) {
      return fmt::format("unsupported property type '{}'", Shown(tokens[1]));
    }
    property.name = std::string(tokens[2]);
  }
  if (HasControlByte(property.name)) {
    return fmt::format("property name '{}' has a control character", Shown(property.name));
  }
  header.elements.back().properties.push_back(std::move(property));
  return {};
}

// A header line after the first; sets `ended` at end_header.
std::string ParseHeaderLine(const std::vector<std::string_view>& tokens, Header& header,
                            bool& have_format, bool& ended) {
  if (tokens.empty()) return "empty line in the header";
  const std::string_view keyword = tokens[0];
  if (keyword == "comment" || keyword == "obj_info") return {};
  if (keyword == "format") return ParseFormatLine(tokens, have_format, header);
  if (keyword == "element") return ParseElementLine(tokens, header);
  if (keyword == "property") return ParsePropertyLine(tokens, header);
  if (keyword == "end_header") {
    if (tokens.size() != 1) return "unexpected text after end_header";
    ended = true;
    return {};
  }
  return fmt::format("unknown header line '{}'", Shown(keyword));
}

// Hostile counts: the `available` bytes of the body must be able to hold every record at its
// smallest.
Status CheckElementCounts(const Header& header, std::uint64_t available, const std::string& name) {
  std::uint64_t needed = 0;
  for (const Element& element : header.elements) {
    if (element.count == 0) continue;
    const std::uint64_t minimum = element.MinimumSize(header.format);
    if (minimum == 0) {
      return Status::Error(fmt::format("{}: element '{}' has {} records but no properties", name,
                                       element.name, element.count));
    }
    const std::uint64_t room = available + (header.format == Format::kAscii ? 1 : 0);
    if (element.count > (room - std::min(room, needed)) / minimum) {
      return Status::Error(fmt::format(
          "{}: header claims {} '{}' elements but the {} bytes after the header hold at most {}",
          name, element.count, element.name, available, (room - std::min(room, needed)) / minimum));
    }
    needed += element.count * minimum;
  }
  return Status::Ok();
}

}  // namespace

int SizeOf(Type type) {
  for (const TypeInfo& info : kTypes) {
    if (info.type == type) return info.size;
  }
  return 0;
}

bool IsInteger(Type type) {
  return type != Type::kFloat32 && type != Type::kFloat64;
}

std::string_view TypeName(Type type) {
  for (const TypeInfo& info : kTypes) {
    if (info.type == type) return info.name;
  }
  return "?";
}

int Element::Find(std::string_view property_name) const {
  for (std::size_t i = 0; i < properties.size(); ++i) {
    if (properties[i].name == property_name) return static_cast<int>(i);
  }
  return -1;
}

std::size_t Element::FixedSize() const {
  std::size_t size = 0;
  for (const Property& p : properties) {
    if (p.is_list) return 0;
    size += static_cast<std::size_t>(SizeOf(p.type));
  }
  return size;
}

std::size_t Element::MinimumSize(Format format) const {
  if (format == Format::kAscii) return 2 * properties.size();  // a digit and a separator each
  std::size_t size = 0;
  for (const Property& p : properties) {
    size += static_cast<std::size_t>(SizeOf(p.is_list ? p.count_type : p.type));
  }
  return size;
}

StatusOr<Header> ParseHeader(std::string_view bytes, const std::string& name) {
  Header header;
  std::size_t pos = 0;
  std::int64_t line = 0;
  bool have_format = false;
  bool ended = false;
  while (pos < bytes.size() && !ended) {
    const std::size_t newline = bytes.find('\n', pos);
    if (newline == std::string_view::npos) break;  // a header line always ends with '\n'
    std::string_view text = bytes.substr(pos, newline - pos);
    pos = newline + 1;
    ++line;
    const std::vector<std::string_view> tokens = SplitBlanks(text);
    if (line == 1) {
      if (tokens.size() != 1 || tokens[0] != "ply") {
        return Status::Error(name + ": not a PLY file (the first line is not 'ply')");
      }
      continue;
    }
    const std::string problem = ParseHeaderLine(tokens, header, have_format, ended);
    if (!problem.empty()) return Status::Error(fmt::format("{}:{}: {}", name, line, problem));
  }
  if (line == 0 && !bytes.empty() && bytes.substr(0, 3) != "ply") {
    return Status::Error(name + ": not a PLY file (the first line is not 'ply')");
  }
  if (!ended) return Status::Error(name + ": PLY header has no end_header line");
  if (!have_format) return Status::Error(name + ": PLY header has no format line");
  header.body_offset = pos;
  header.body_first_line = line + 1;
  DISPEX_RETURN_IF_ERROR(CheckElementCounts(header, bytes.size() - pos, name));
  return header;
}

}  // namespace dispex::mesh
