// The PLY reader (format: see ply_header.h): ASCII and both binary byte orders.
//
// Only `vertex` (x, y, z of any numeric type) and `face` (a `vertex_indices` or
// `vertex_index` list of any integer types) are kept; every other property and element is
// stepped over. Binary files are read in two steps: a walk that finds where each element
// starts, sizes every face and checks that the file holds them (sequential: list sizes chain
// the offsets), then a parallel pass over blocks of vertices and faces that converts the
// values and checks each index. ASCII files are read token by token in one sequential pass.
// Errors name the file, the element and its index (and the line, for ASCII).
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <optional>
#include <vector>

#include "core/check.h"
#include "core/first_error.h"
#include "core/first_touch.h"
#include "core/mapped_file.h"
#include "core/parallel.h"
#include "dispex/mesh.h"
#include "mesh/ply_header.h"
#include "mesh/text_scan.h"

namespace dispex {
namespace {

using mesh::Element;
using mesh::Format;
using mesh::Header;
using mesh::Property;
using mesh::Type;

constexpr std::size_t kBlock = 1 << 16;  // vertices or faces per parallel task

// ---- Binary values ---------------------------------------------------------------------

template <class U>
U LoadUnsigned(const unsigned char* p, bool swap) {
  U v;
  std::memcpy(&v, p, sizeof v);
  if (swap) {
    if constexpr (sizeof(U) == 2) v = __builtin_bswap16(v);
    if constexpr (sizeof(U) == 4) v = __builtin_bswap32(v);
    if constexpr (sizeof(U) == 8) v = __builtin_bswap64(v);
  }
  return v;
}

// An integer-typed value (the caller checked the type is an integer type).
std::int64_t LoadInt(const unsigned char* p, Type type, bool swap) {
  switch (type) {
    case Type::kInt8:
      return static_cast<std::int8_t>(p[0]);
    case Type::kUint8:
      return p[0];
    case Type::kInt16:
      return static_cast<std::int16_t>(LoadUnsigned<std::uint16_t>(p, swap));
    case Type::kUint16:
      return LoadUnsigned<std::uint16_t>(p, swap);
    case Type::kInt32:
      return static_cast<std::int32_t>(LoadUnsigned<std::uint32_t>(p, swap));
    case Type::kUint32:
      return LoadUnsigned<std::uint32_t>(p, swap);
    case Type::kFloat32:
    case Type::kFloat64:
      break;
  }
  DISPEX_CHECK(false);
  return 0;
}

double LoadReal(const unsigned char* p, Type type, bool swap) {
  if (type == Type::kFloat32) return std::bit_cast<float>(LoadUnsigned<std::uint32_t>(p, swap));
  if (type == Type::kFloat64) return std::bit_cast<double>(LoadUnsigned<std::uint64_t>(p, swap));
  return static_cast<double>(LoadInt(p, type, swap));
}

// A coordinate as float, or an error message.
std::optional<std::string> ToCoordinate(double value, float& out) {
  if (!std::isfinite(value)) return fmt::format("coordinate {} is not a finite number", value);
  if (std::fabs(value) > static_cast<double>(FLT_MAX)) {
    return fmt::format("coordinate {} does not fit a float", value);
  }
  out = static_cast<float>(value);
  return std::nullopt;
}

// ---- What we keep of the header ---------------------------------------------------------

struct Layout {
  int vertex_element = -1;
  int x = -1, y = -1, z = -1;  // property indices in the vertex element
  int face_element = -1;
  int indices = -1;  // the index list in the face element
  std::uint64_t num_vertices = 0;
  std::uint64_t num_faces = 0;
};

StatusOr<Layout> FindLayout(const Header& header, const std::string& name) {
  Layout layout;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const Element& element = header.elements[e];
    if (element.name == "vertex" && layout.vertex_element < 0) {
      layout.vertex_element = static_cast<int>(e);
    } else if (element.name == "face" && layout.face_element < 0) {
      layout.face_element = static_cast<int>(e);
    }
  }
  if (layout.vertex_element < 0) return Status::Error(name + ": PLY has no 'vertex' element");
  const Element& vertex = header.elements[static_cast<std::size_t>(layout.vertex_element)];
  int* axes[3] = {&layout.x, &layout.y, &layout.z};
  const char* axis_names[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    *axes[k] = vertex.Find(axis_names[k]);
    if (*axes[k] < 0) {
      return Status::Error(
          fmt::format("{}: PLY vertex element has no '{}' property", name, axis_names[k]));
    }
    if (vertex.properties[static_cast<std::size_t>(*axes[k])].is_list) {
      return Status::Error(
          fmt::format("{}: PLY vertex property '{}' is a list", name, axis_names[k]));
    }
  }
  layout.num_vertices = vertex.count;
  if (layout.face_element < 0) {
    return Status::Error(name + ": PLY has no 'face' element: no faces");
  }
  const Element& face = header.elements[static_cast<std::size_t>(layout.face_element)];
  layout.indices = face.Find("vertex_indices");
  if (layout.indices < 0) layout.indices = face.Find("vertex_index");
  if (layout.indices < 0) {
    return Status::Error(name + ": PLY face element has no 'vertex_indices' list");
  }
  const Property& list = face.properties[static_cast<std::size_t>(layout.indices)];
  if (!list.is_list) {
    return Status::Error(fmt::format("{}: PLY face property '{}' is not a list", name, list.name));
  }
  if (!mesh::IsInteger(list.type)) {
    return Status::Error(fmt::format("{}: PLY face index type '{}' is not an integer type", name,
                                     mesh::TypeName(list.type)));
  }
  layout.num_faces = face.count;
  if (layout.num_faces == 0) return Status::Error(name + ": PLY has no faces");
  if (layout.num_vertices > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max()) ||
      layout.num_faces > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
    return Status::Error(name + ": more than 2^31-1 vertices or faces");
  }
  return layout;
}

// ---- Binary ------------------------------------------------------------------------------

class BinaryReader {
 public:
  BinaryReader(std::string_view bytes, const std::string& name, const Header& header,
               const Layout& layout, int threads)
      : data_(reinterpret_cast<const unsigned char*>(bytes.data())),
        size_(bytes.size()),
        name_(name),
        header_(header),
        layout_(layout),
        threads_(threads),
        swap_((header.format == Format::kBinaryBigEndian) !=
              (std::endian::native == std::endian::big)) {}

  StatusOr<Mesh> Read() {
    Mesh mesh;
    mesh.source = name_;
    std::size_t pos = header_.body_offset;
    for (std::size_t e = 0; e < header_.elements.size(); ++e) {
      const Element& element = header_.elements[e];
      const std::size_t start = pos;
      if (static_cast<int>(e) == layout_.face_element) {
        const bool last = e + 1 == header_.elements.size();
        if (!last || !LayOutUniformFaces(element, pos, mesh)) {
          DISPEX_RETURN_IF_ERROR(SizeFaces(element, pos, mesh));
        }
      } else {
        DISPEX_RETURN_IF_ERROR(Skip(element, pos));
      }
      starts_.push_back(start);
    }
    DISPEX_RETURN_IF_ERROR(ReadVertices(mesh));
    bool uniform_broken = false;
    Status faces = ReadFaces(mesh, uniform_broken);
    if (uniform_broken) {  // a face of another size: walked record by record after all
      uniform_corners_ = 0;
      face_block_starts_.clear();
      std::size_t at = starts_[static_cast<std::size_t>(layout_.face_element)];
      DISPEX_RETURN_IF_ERROR(
          SizeFaces(header_.elements[static_cast<std::size_t>(layout_.face_element)], at, mesh));
      faces = ReadFaces(mesh, uniform_broken);
    }
    DISPEX_RETURN_IF_ERROR(faces);
    return mesh;
  }

 private:
  Status Truncated(const Element& element, std::uint64_t index) const {
    return Status::Error(fmt::format("{}: {} {}: truncated (the file ends after {} bytes)", name_,
                                     element.name, index, size_));
  }

  // Steps over one record's property; false if the file ends inside it.
  bool StepProperty(const Property& property, std::size_t& pos, std::int64_t* list_size) const {
    if (!property.is_list) {
      const std::size_t size = static_cast<std::size_t>(mesh::SizeOf(property.type));
      if (size_ - pos < size) return false;
      pos += size;
      return true;
    }
    const std::size_t count_size = static_cast<std::size_t>(mesh::SizeOf(property.count_type));
    if (size_ - pos < count_size) return false;
    const std::int64_t count = LoadInt(data_ + pos, property.count_type, swap_);
    pos += count_size;
    *list_size = count;
    if (count < 0) return true;  // the caller reports it
    const std::size_t item = static_cast<std::size_t>(mesh::SizeOf(property.type));
    if (static_cast<std::uint64_t>(count) > (size_ - pos) / item) return false;
    pos += static_cast<std::size_t>(count) * item;
    return true;
  }

  Status Skip(const Element& element, std::size_t& pos) const {
    const std::size_t fixed = element.FixedSize();
    if (fixed > 0) {
      const std::uint64_t fit = (size_ - pos) / fixed;
      if (fit < element.count) return Truncated(element, fit);
      pos += static_cast<std::size_t>(element.count) * fixed;
      return Status::Ok();
    }
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (const Property& property : element.properties) {
        std::int64_t list_size = 0;
        if (!StepProperty(property, pos, &list_size)) return Truncated(element, i);
        if (list_size < 0) {
          return Status::Error(fmt::format("{}: {} {}: negative list size {} for '{}'", name_,
                                           element.name, i, list_size, property.name));
        }
      }
    }
    return Status::Ok();
  }

  // Faces as records of one size: the vertex index list alone, every face with the first
  // face's corner count (a sculpt of quads or triangles). Laid out without a walk over the
  // records; ReadFaces checks each face's count and says when one differs. False when the first
  // record, the file's length or the corner total rule it out (SizeFaces then walks, and names
  // what is wrong).
  bool LayOutUniformFaces(const Element& element, std::size_t& pos, Mesh& mesh) {
    if (element.properties.size() != 1 || layout_.indices != 0 || element.count == 0) return false;
    const Property& list = element.properties[0];
    const std::size_t count_size = static_cast<std::size_t>(mesh::SizeOf(list.count_type));
    const std::size_t item_size = static_cast<std::size_t>(mesh::SizeOf(list.type));
    if (size_ - pos < count_size) return false;
    const std::int64_t corners = LoadInt(data_ + pos, list.count_type, swap_);
    if (corners < 3) return false;
    const std::uint64_t record = count_size + static_cast<std::uint64_t>(corners) * item_size;
    if ((size_ - pos) / record < element.count ||
        element.count * static_cast<std::uint64_t>(corners) >
            std::numeric_limits<std::uint32_t>::max()) {
      return false;
    }
    const std::size_t n = static_cast<std::size_t>(element.count);
    RunWithThreads(threads_, [&] {
      AssignTouched(mesh.face_offsets, n + 1, 0u);
      tbb::parallel_for(std::size_t{0}, n + 1, [&](std::size_t f) {
        mesh.face_offsets[f] = static_cast<std::uint32_t>(f * static_cast<std::size_t>(corners));
      });
    });
    for (std::size_t f = 0; f < n; f += kBlock) face_block_starts_.push_back(pos + f * record);
    pos += static_cast<std::size_t>(element.count * record);
    uniform_corners_ = corners;
    return true;
  }

  // Walks the face records: face sizes into face_offsets, a record start every kBlock faces.
  Status SizeFaces(const Element& element, std::size_t& pos, Mesh& mesh) {
    RunWithThreads(threads_, [&] {
      AssignTouched(mesh.face_offsets, static_cast<std::size_t>(element.count) + 1, 0u);
    });
    std::uint64_t corners = 0;
    for (std::uint64_t f = 0; f < element.count; ++f) {
      if (f % kBlock == 0) face_block_starts_.push_back(pos);
      for (std::size_t k = 0; k < element.properties.size(); ++k) {
        const Property& property = element.properties[k];
        std::int64_t list_size = 0;
        if (!StepProperty(property, pos, &list_size)) return Truncated(element, f);
        if (list_size < 0) {
          return Status::Error(fmt::format("{}: face {}: negative list size {} for '{}'", name_, f,
                                           list_size, property.name));
        }
        if (static_cast<int>(k) == layout_.indices) {
          if (list_size < 3) {
            return Status::Error(
                fmt::format("{}: face {}: {} vertices (at least 3 needed)", name_, f, list_size));
          }
          corners += static_cast<std::uint64_t>(list_size);
          if (corners > std::numeric_limits<std::uint32_t>::max()) {
            return Status::Error(
                fmt::format("{}: face {}: more than 2^32-1 face corners in the file", name_, f));
          }
          mesh.face_offsets[f + 1] = static_cast<std::uint32_t>(corners);
        }
      }
    }
    return Status::Ok();
  }

  Status ReadVertices(Mesh& mesh) const {
    const Element& element = header_.elements[static_cast<std::size_t>(layout_.vertex_element)];
    const std::size_t n = static_cast<std::size_t>(element.count);
    // Embree reads 16 bytes at the last vertex.
    RunWithThreads(threads_, [&] { ReserveTouched(mesh.positions, n + 1); });
    mesh.positions.resize(n);
    const std::size_t start = starts_[static_cast<std::size_t>(layout_.vertex_element)];
    const int axes[3] = {layout_.x, layout_.y, layout_.z};
    const std::size_t fixed = element.FixedSize();
    std::size_t offsets[3] = {0, 0, 0};  // of x, y, z within a fixed-size record
    for (int k = 0; k < 3 && fixed > 0; ++k) {
      for (int j = 0; j < axes[k]; ++j) {
        offsets[k] += static_cast<std::size_t>(
            mesh::SizeOf(element.properties[static_cast<std::size_t>(j)].type));
      }
    }
    // Converts vertex v whose x, y, z values start at the byte offsets `at`.
    auto convert = [&](std::size_t v, const std::size_t(&at)[3], FirstError& error) {
      float xyz[3];
      for (int k = 0; k < 3; ++k) {
        const Type type = element.properties[static_cast<std::size_t>(axes[k])].type;
        if (auto message = ToCoordinate(LoadReal(data_ + at[k], type, swap_), xyz[k])) {
          error.Record(std::int64_t(v),
                       Status::Error(fmt::format("{}: vertex {}: {}", name_, v, *message)));
          return false;
        }
      }
      mesh.positions[v] = Float3{xyz[0], xyz[1], xyz[2]};
      return true;
    };
    FirstError error;
    if (fixed > 0) {
      RunWithThreads(threads_, [&] {
        tbb::parallel_for(std::size_t{0}, (n + kBlock - 1) / kBlock, [&](std::size_t b) {
          for (std::size_t v = b * kBlock; v < std::min(n, (b + 1) * kBlock); ++v) {
            const std::size_t record = start + v * fixed;
            const std::size_t at[3] = {record + offsets[0], record + offsets[1],
                                       record + offsets[2]};
            if (!convert(v, at, error)) return;
          }
        });
      });
    } else {
      // Lists in the vertex element (rare): records have no fixed stride, walk them.
      std::size_t pos = start;
      for (std::size_t v = 0; v < n && !error.failed(); ++v) {
        std::size_t at[3] = {0, 0, 0};
        for (std::size_t k = 0; k < element.properties.size(); ++k) {
          for (int axis = 0; axis < 3; ++axis) {
            if (static_cast<int>(k) == axes[axis]) at[axis] = pos;
          }
          std::int64_t unused = 0;
          DISPEX_CHECK(StepProperty(element.properties[k], pos, &unused));  // walked before
        }
        convert(v, at, error);
      }
    }
    if (error.failed()) return error.status();
    return Status::Ok();
  }

  // `uniform_broken`: set when the faces were laid out as one size (LayOutUniformFaces) and
  // one is not; the indices read are then not the file's, and the status means nothing.
  Status ReadFaces(Mesh& mesh, bool& uniform_broken) const {
    const Element& element = header_.elements[static_cast<std::size_t>(layout_.face_element)];
    const std::size_t n = static_cast<std::size_t>(element.count);
    RunWithThreads(threads_,
                   [&] { AssignTouched(mesh.face_indices, mesh.face_offsets.back(), 0); });
    const Property& list = element.properties[static_cast<std::size_t>(layout_.indices)];
    const std::size_t count_size = static_cast<std::size_t>(mesh::SizeOf(list.count_type));
    const std::size_t item_size = static_cast<std::size_t>(mesh::SizeOf(list.type));
    const std::int64_t num_vertices = static_cast<std::int64_t>(layout_.num_vertices);
    FirstError error;
    std::atomic<bool> broken{false};
    RunWithThreads(threads_, [&] {
      tbb::parallel_for(std::size_t{0}, face_block_starts_.size(), [&](std::size_t b) {
        std::size_t pos = face_block_starts_[b];
        for (std::size_t f = b * kBlock; f < std::min(n, (b + 1) * kBlock); ++f) {
          for (std::size_t k = 0; k < element.properties.size(); ++k) {
            if (static_cast<int>(k) != layout_.indices) {
              std::int64_t unused = 0;
              DISPEX_CHECK(StepProperty(element.properties[k], pos, &unused));  // walked before
              continue;
            }
            if (uniform_corners_ > 0 &&
                LoadInt(data_ + pos, list.count_type, swap_) != uniform_corners_) {
              broken.store(true, std::memory_order_relaxed);
              return;
            }
            pos += count_size;
            std::int32_t* out = mesh.face_indices.data() + mesh.face_offsets[f];
            const std::uint32_t size = mesh.face_offsets[f + 1] - mesh.face_offsets[f];
            for (std::uint32_t i = 0; i < size; ++i, pos += item_size) {
              const std::int64_t index = LoadInt(data_ + pos, list.type, swap_);
              if (index < 0 || index >= num_vertices) {
                error.Record(std::int64_t(f),
                             Status::Error(fmt::format(
                                 "{}: face {}: vertex index {} out of range ({} vertices)", name_,
                                 f, index, num_vertices)));
                return;
              }
              out[i] = static_cast<std::int32_t>(index);
            }
          }
        }
      });
    });
    uniform_broken = broken.load();
    if (error.failed()) return error.status();
    return Status::Ok();
  }

  const unsigned char* data_;
  std::size_t size_;
  const std::string& name_;
  const Header& header_;
  const Layout& layout_;
  int threads_;
  bool swap_;
  std::vector<std::size_t> starts_;             // byte offset of each element
  std::vector<std::size_t> face_block_starts_;  // byte offset of face b * kBlock
  std::int64_t uniform_corners_ = 0;            // LayOutUniformFaces' corners per face, or 0
};

// ---- ASCII -------------------------------------------------------------------------------

class AsciiReader {
 public:
  AsciiReader(std::string_view bytes, const std::string& name, const Header& header,
              const Layout& layout)
      : p_(bytes.data() + header.body_offset),
        end_(bytes.data() + bytes.size()),
        line_(header.body_first_line),
        name_(name),
        header_(header),
        layout_(layout) {}

  StatusOr<Mesh> Read() {
    Mesh mesh;
    mesh.source = name_;
    mesh.positions.reserve(static_cast<std::size_t>(layout_.num_vertices) + 1);
    mesh.positions.resize(static_cast<std::size_t>(layout_.num_vertices));
    mesh.face_offsets.reserve(static_cast<std::size_t>(layout_.num_faces) + 1);
    mesh.face_offsets.push_back(0);
    mesh.face_indices.reserve(static_cast<std::size_t>(layout_.num_faces) * 3);
    for (std::size_t e = 0; e < header_.elements.size(); ++e) {
      const Element& element = header_.elements[e];
      const bool is_vertex = static_cast<int>(e) == layout_.vertex_element;
      const bool is_face = static_cast<int>(e) == layout_.face_element;
      for (std::uint64_t i = 0; i < element.count; ++i) {
        float xyz[3] = {0, 0, 0};
        for (std::size_t k = 0; k < element.properties.size(); ++k) {
          const Property& property = element.properties[k];
          const int axis = !is_vertex                         ? -1
                           : static_cast<int>(k) == layout_.x ? 0
                           : static_cast<int>(k) == layout_.y ? 1
                           : static_cast<int>(k) == layout_.z ? 2
                                                              : -1;
          if (!property.is_list) {
            double value = 0;
            DISPEX_RETURN_IF_ERROR(Value(element, i, property, property.type, value));
            if (axis >= 0) {
              if (auto message = ToCoordinate(value, xyz[axis])) return Fail(element, i, *message);
            }
            continue;
          }
          double count_value = 0;
          DISPEX_RETURN_IF_ERROR(Value(element, i, property, property.count_type, count_value));
          const std::int64_t count = static_cast<std::int64_t>(count_value);
          if (count < 0) {
            return Fail(element, i,
                        fmt::format("negative list size {} for '{}'", count, property.name));
          }
          const bool indices = is_face && static_cast<int>(k) == layout_.indices;
          if (indices && count < 3) {
            return Fail(element, i, fmt::format("{} vertices (at least 3 needed)", count));
          }
          for (std::int64_t j = 0; j < count; ++j) {
            double value = 0;
            DISPEX_RETURN_IF_ERROR(Value(element, i, property, property.type, value));
            if (!indices) continue;
            if (value < 0 || value >= static_cast<double>(layout_.num_vertices)) {
              return Fail(element, i,
                          fmt::format("vertex index {} out of range ({} vertices)",
                                      static_cast<std::int64_t>(value), layout_.num_vertices));
            }
            mesh.face_indices.push_back(static_cast<std::int32_t>(value));
          }
          if (indices) {
            if (mesh.face_indices.size() > std::numeric_limits<std::uint32_t>::max()) {
              return Fail(element, i, "more than 2^32-1 face corners in the file");
            }
            mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
          }
        }
        if (is_vertex) mesh.positions[i] = Float3{xyz[0], xyz[1], xyz[2]};
      }
    }
    SkipSpace();
    if (p_ != end_) {
      return Status::Error(fmt::format("{}:{}: unexpected '{}' after the last element", name_,
                                       line_, mesh::TokenForMessage(p_, end_)));
    }
    return mesh;
  }

 private:
  Status Fail(const Element& element, std::uint64_t index, const std::string& message) const {
    return Status::Error(
        fmt::format("{}:{}: {} {}: {}", name_, line_, element.name, index, message));
  }

  void SkipSpace() {
    while (p_ < end_ && (mesh::IsBlank(*p_) || *p_ == '\n')) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
  }

  // Reads the next token as a value of `type`: integers exactly, reals finite. Integer-typed
  // values must be integers within the type's range.
  Status Value(const Element& element, std::uint64_t index, const Property& property, Type type,
               double& value) {
    SkipSpace();
    if (p_ == end_) {
      return Fail(element, index, fmt::format("file ends before its '{}' value", property.name));
    }
    const char* token = p_;
    if (mesh::IsInteger(type)) {
      std::int64_t v = 0;
      const mesh::NumberResult r = mesh::ParseInt(p_, end_, v);
      if (r != mesh::NumberResult::kOk || !EndsValue()) {
        p_ = token;
        return Fail(element, index,
                    fmt::format("bad {} value '{}' for '{}'", mesh::TypeName(type),
                                mesh::TokenForMessage(p_, end_), property.name));
      }
      const int bits = mesh::SizeOf(type) * 8;
      const bool is_signed = type == Type::kInt8 || type == Type::kInt16 || type == Type::kInt32;
      const std::int64_t lo = is_signed ? -(std::int64_t{1} << (bits - 1)) : 0;
      const std::int64_t hi =
          is_signed ? (std::int64_t{1} << (bits - 1)) - 1 : (std::int64_t{1} << bits) - 1;
      if (v < lo || v > hi) {
        p_ = token;
        return Fail(element, index,
                    fmt::format("value {} of '{}' does not fit its type {}", v, property.name,
                                mesh::TypeName(type)));
      }
      value = static_cast<double>(v);
      return Status::Ok();
    }
    mesh::NumberResult r;
    if (type == Type::kFloat32) {
      float f = 0;
      r = mesh::ParseReal(p_, end_, f);
      value = f;
    } else {
      r = mesh::ParseReal(p_, end_, value);
    }
    if (r == mesh::NumberResult::kOk && EndsValue()) return Status::Ok();
    p_ = token;
    if (r == mesh::NumberResult::kNotFinite) {
      return Fail(element, index,
                  fmt::format("'{}' value '{}' is not a finite number", property.name,
                              mesh::TokenForMessage(p_, end_)));
    }
    return Fail(element, index,
                fmt::format("bad {} value '{}' for '{}'", mesh::TypeName(type),
                            mesh::TokenForMessage(p_, end_), property.name));
  }

  bool EndsValue() const { return p_ == end_ || mesh::IsBlank(*p_) || *p_ == '\n'; }

  const char* p_;
  const char* end_;
  std::int64_t line_;
  const std::string& name_;
  const Header& header_;
  const Layout& layout_;
};

}  // namespace

StatusOr<Mesh> ParsePly(std::string_view bytes, const std::string& name,
                        const ReadOptions& options) {
  DISPEX_ASSIGN_OR_RETURN(const Header header, mesh::ParseHeader(bytes, name));
  DISPEX_ASSIGN_OR_RETURN(const Layout layout, FindLayout(header, name));
  if (header.format == Format::kAscii) return AsciiReader(bytes, name, header, layout).Read();
  return BinaryReader(bytes, name, header, layout, options.threads).Read();
}

StatusOr<Mesh> ReadPly(const std::string& path, const ReadOptions& options) {
  DISPEX_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  return ParsePly(file.view(), path, options);
}

}  // namespace dispex
