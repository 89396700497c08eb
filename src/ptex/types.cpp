// Names, sizes and meta data value accessors of the public Ptex types.
#include <cstring>

#include "core/enum_names.h"
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

namespace {

constexpr auto kDataTypeNames = EnumTable<PtexDataType>({
    {PtexDataType::kUint8, "uint8"},
    {PtexDataType::kUint16, "uint16"},
    {PtexDataType::kHalf, "half"},
    {PtexDataType::kFloat, "float32"},
});
constexpr auto kMeshTypeNames = EnumTable<PtexMeshType>({
    {PtexMeshType::kTriangle, "triangle"},
    {PtexMeshType::kQuad, "quad"},
});
constexpr auto kBorderModeNames = EnumTable<PtexBorderMode>({
    {PtexBorderMode::kClamp, "clamp"},
    {PtexBorderMode::kBlack, "black"},
    {PtexBorderMode::kPeriodic, "periodic"},
});
constexpr auto kEdgeFilterModeNames = EnumTable<PtexEdgeFilterMode>({
    {PtexEdgeFilterMode::kNone, "none"},
    {PtexEdgeFilterMode::kTangentVector, "tanvec"},
});
constexpr auto kMetaTypeNames = EnumTable<PtexMetaType>({
    {PtexMetaType::kString, "string"},
    {PtexMetaType::kInt8, "int8"},
    {PtexMetaType::kInt16, "int16"},
    {PtexMetaType::kInt32, "int32"},
    {PtexMetaType::kFloat, "float"},
    {PtexMetaType::kDouble, "double"},
});

}  // namespace

std::string_view PtexDataTypeName(PtexDataType type) {
  return EnumName(kDataTypeNames, type);
}

std::string_view PtexMeshTypeName(PtexMeshType type) {
  return EnumName(kMeshTypeNames, type);
}

std::string_view PtexBorderModeName(PtexBorderMode mode) {
  return EnumName(kBorderModeNames, mode);
}

std::string_view PtexEdgeFilterModeName(PtexEdgeFilterMode mode) {
  return EnumName(kEdgeFilterModeNames, mode);
}

std::string_view PtexMetaTypeName(PtexMetaType type) {
  return EnumName(kMetaTypeNames, type);
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
