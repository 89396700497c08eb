// The header of a PLY file (Greg Turk's "The PLY Polygon File Format", 1994, and the
// property type names of later writers: int8/uint8/.../float32/float64).
//
//   ply
//   format ascii 1.0 | binary_little_endian 1.0 | binary_big_endian 1.0
//   comment ... | obj_info ...
//   element <name> <count>
//   property <type> <name>                              (scalar)
//   property list <count type> <item type> <name>      (list)
//   end_header
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/status.h"

namespace dispex::mesh {

enum class Format : std::uint8_t { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

enum class Type : std::uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};

int SizeOf(Type type);
bool IsInteger(Type type);
std::string_view TypeName(Type type);

struct Property {
  std::string name;
  bool is_list = false;
  Type type = Type::kFloat32;      // the value type (item type for lists)
  Type count_type = Type::kUint8;  // lists only
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;

  // Index of the property called `name`, or -1.
  int Find(std::string_view property_name) const;
  // Bytes of one binary record when it has no lists, else 0.
  std::size_t FixedSize() const;
  // The fewest bytes one record can take in the file's format (lists empty).
  std::size_t MinimumSize(Format format) const;
};

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;       // first byte after "end_header\n"
  std::int64_t body_first_line = 0;  // 1-based line number of the body's first line
};

// Parses the header of `bytes`. Errors name the file and the header line. Also rejects
// element counts that the rest of the file cannot possibly hold, before anything is
// allocated for them.
StatusOr<Header> ParseHeader(std::string_view bytes, const std::string& name);

}  // namespace dispex::mesh
