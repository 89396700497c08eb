// Names, sizes and meta data value accessors of the public Ptex types.
#include <cstring>

#include "dispex/ptex.h"
#include "ptex/meta_data.h"

namespace dispex {

int PtexDataSize(PtexDataType type) {
  switch (type) {
    case PtexDataType::kUint8:
      return 1;
    case PtexDataType::kUint16:
    case PtexDataType::kHalf:
      return 2;
    case PtexDataType::kFloat:
      return 4;
  }
  return 1;
}

std::string_view PtexDataTypeName(PtexDataType type) {
  switch (type) {
    case PtexDataType::kUint8:
      return "uint8";
    case PtexDataType::kUint16:
      return "uint16";
    case PtexDataType::kHalf:
      return "half";
    case PtexDataType::kFloat:
      return "float32";
  }
  return "?";
}

std::string_view PtexMeshTypeName(PtexMeshType type) {
  return type == PtexMeshType::kTriangle ? "triangle" : "quad";
}

std::string_view PtexBorderModeName(PtexBorderMode mode) {
  switch (mode) {
    case PtexBorderMode::kClamp:
      return "clamp";
    case PtexBorderMode::kBlack:
      return "black";
    case PtexBorderMode::kPeriodic:
      return "periodic";
  }
  return "?";
}

std::string_view PtexEdgeFilterModeName(PtexEdgeFilterMode mode) {
  return mode == PtexEdgeFilterMode::kTangentVector ? "tanvec" : "none";
}

std::string_view PtexMetaTypeName(PtexMetaType type) {
  switch (type) {
    case PtexMetaType::kString:
      return "string";
    case PtexMetaType::kInt8:
      return "int8";
    case PtexMetaType::kInt16:
      return "int16";
    case PtexMetaType::kInt32:
      return "int32";
    case PtexMetaType::kFloat:
      return "float";
    case PtexMetaType::kDouble:
      return "double";
  }
  return "?";
}

namespace {
template <class T>
std::vector<T> Values(const PtexMetaItem& item, PtexMetaType want) {
  std::vector<T> out;
  if (item.type != want) return out;
  out.resize(item.bytes.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), item.bytes.data(), out.size() * sizeof(T));
  return out;
}
}  // namespace

std::size_t PtexMetaItem::count() const {
  if (type == PtexMetaType::kString) return 1;
  return bytes.size() / ptex::MetaElementSize(type);
}

std::string PtexMetaItem::AsString() const {
  if (type != PtexMetaType::kString) return {};
  std::size_t n = 0;
  while (n < bytes.size() && bytes[n] != 0) ++n;
  return std::string(reinterpret_cast<const char*>(bytes.data()), n);
}

std::vector<std::int8_t> PtexMetaItem::AsInt8() const {
  return Values<std::int8_t>(*this, PtexMetaType::kInt8);
}
std::vector<std::int16_t> PtexMetaItem::AsInt16() const {
  return Values<std::int16_t>(*this, PtexMetaType::kInt16);
}
std::vector<std::int32_t> PtexMetaItem::AsInt32() const {
  return Values<std::int32_t>(*this, PtexMetaType::kInt32);
}
std::vector<float> PtexMetaItem::AsFloat() const {
  return Values<float>(*this, PtexMetaType::kFloat);
}
std::vector<double> PtexMetaItem::AsDouble() const {
  return Values<double>(*this, PtexMetaType::kDouble);
}

std::vector<double> PtexMetaItem::AsNumbers() const {
  auto widen = [](const auto& v) { return std::vector<double>(v.begin(), v.end()); };
  switch (type) {
    case PtexMetaType::kString:
      return {};
    case PtexMetaType::kInt8:
      return widen(AsInt8());
    case PtexMetaType::kInt16:
      return widen(AsInt16());
    case PtexMetaType::kInt32:
      return widen(AsInt32());
    case PtexMetaType::kFloat:
      return widen(AsFloat());
    case PtexMetaType::kDouble:
      return AsDouble();
  }
  return {};
}

}  // namespace dispex
