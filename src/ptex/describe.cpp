#include "ptex/describe.h"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "core/enum_names.h"
#include "ptex/format.h"

namespace dispex::ptex {

namespace {

std::string AdjacencyText(const PtexFaceInfo& info, int edges) {
  std::string s = "[";
  for (int e = 0; e < edges; ++e) {
    if (e) s += ' ';
    s += info.adjfaces[e] < 0 ? std::string("-")
                              : fmt::format("{}:{}", info.adjfaces[e], info.adjedges[e]);
  }
  return s + "]";
}

std::string FlagsText(const PtexFaceInfo& info) {
  std::vector<std::string> flags;
  if (info.constant) flags.emplace_back("constant");
  if (info.subface) flags.emplace_back("subface");
  if (info.neighborhood_constant) flags.emplace_back("nbconstant");
  if (info.has_edits) flags.emplace_back("edited");
  return flags.empty() ? std::string("-") : fmt::format("{}", fmt::join(flags, ","));
}

// A texel of `count` channels at `p`.
std::string TexelText(const std::uint8_t* p, int channels, PtexDataType type) {
  const int size = PtexDataSize(type);
  if (channels == 1) return FormatRawValue(p, type);
  std::string s = "(";
  for (int c = 0; c < channels; ++c) {
    if (c) s += ' ';
    s += FormatRawValue(p + c * size, type);
  }
  return s + ")";
}

constexpr auto kEncodingNames = EnumTable<PtexBlockInfo::Encoding>({
    {PtexBlockInfo::Encoding::kConstant, "constant"},
    {PtexBlockInfo::Encoding::kZipped, "zipped"},
    {PtexBlockInfo::Encoding::kDiffZipped, "diffzipped"},
    {PtexBlockInfo::Encoding::kTiled, "tiled"},
});

std::string_view EncodingName(PtexBlockInfo::Encoding e) {
  return EnumName(kEncodingNames, e);
}

}  // namespace

std::string FormatRawValue(const std::uint8_t* p, PtexDataType type) {
  switch (type) {
    case PtexDataType::kUint8:
      return fmt::format("{}", p[0]);
    case PtexDataType::kUint16:
      return fmt::format("{}", Load<std::uint16_t>(p));
    case PtexDataType::kHalf:
      return fmt::format("{}", HalfToFloat(Load<std::uint16_t>(p)));
    case PtexDataType::kFloat:
      return fmt::format("{}", Load<float>(p));
  }
  return "?";
}

std::string FormatMetaValue(const PtexMetaItem& item, std::size_t max_values) {
  if (item.type == PtexMetaType::kString) return fmt::format("\"{}\"", item.AsString());
  const std::size_t n = item.count(), shown = std::min(n, max_values);
  std::string s;
  for (std::size_t i = 0; i < shown; ++i) {
    if (i) s += ' ';
    const std::uint8_t* p = item.bytes.data();
    switch (item.type) {
      case PtexMetaType::kInt8:
        s += fmt::format("{}", static_cast<std::int8_t>(p[i]));
        break;
      case PtexMetaType::kInt16:
        s += fmt::format("{}", Load<std::int16_t>(p + 2 * i));
        break;
      case PtexMetaType::kInt32:
        s += fmt::format("{}", Load<std::int32_t>(p + 4 * i));
        break;
      case PtexMetaType::kFloat:
        s += fmt::format("{}", Load<float>(p + 4 * i));
        break;
      case PtexMetaType::kDouble:
        s += fmt::format("{}", Load<double>(p + 8 * i));
        break;
      case PtexMetaType::kString:
        break;
    }
  }
  if (shown < n) s += fmt::format(" ... ({} values)", n);
  return s;
}

}  // namespace dispex::ptex

namespace dispex {

using namespace ptex;  // NOLINT: the helpers above, ReductionOrder

std::string FormatPtexSummary(const PtexFile& file, std::size_t max_values) {
  const PtexHeaderInfo& h = file.header();
  std::size_t constant = 0, subfaces = 0, level0_texels = 0, reduced_texels = 0;
  for (int f = 0; f < h.num_faces; ++f) {
    const PtexFaceInfo& info = file.face_info(PtexFaceId(f));
    constant += info.constant;
    subfaces += info.subface;
    if (info.constant) continue;
    level0_texels += info.num_texels();
    for (int l = 1; l < file.NumStoredLevels(PtexFaceId(f)); ++l) {
      reduced_texels += info.num_texels() >> (2 * l);
    }
  }
  std::string s;
  s += fmt::format("file          {}\n", file.name());
  s += fmt::format("size on disk  {} bytes\n", h.file_size);
  s += fmt::format("format        Ptex 1.{}\n", h.minor_version);
  s += fmt::format("mesh type     {}\n", PtexMeshTypeName(h.mesh_type));
  s += fmt::format("data type     {}\n", PtexDataTypeName(h.data_type));
  s += fmt::format("channels      {}\n", h.num_channels);
  s += fmt::format("alpha         {}\n", h.alpha_channel < 0
                                             ? std::string("none")
                                             : fmt::format("channel {}", h.alpha_channel));
  s +=
      fmt::format("faces         {} ({} constant, {} subfaces)\n", h.num_faces, constant, subfaces);
  s += fmt::format("levels        {} (entries:", h.num_levels);
  for (const PtexLevelInfo& l : file.levels()) s += fmt::format(" {}", l.num_entries);
  s += ")\n";
  s += fmt::format("border modes  u {}, v {}\n", PtexBorderModeName(h.u_border),
                   PtexBorderModeName(h.v_border));
  s += fmt::format("edge filter   {}\n", PtexEdgeFilterModeName(h.edge_filter));
  s += fmt::format("texels        {} at level 0 in non-constant faces, {} in reductions\n",
                   level0_texels, reduced_texels);
  s += fmt::format("edits         {}\n", h.has_edits ? "yes" : "no");
  s += fmt::format("meta data     {} items\n", file.meta_data().size());
  for (const PtexMetaItem& item : file.meta_data()) {
    s += fmt::format("  {} {}[{}]{}: {}\n", item.key, PtexMetaTypeName(item.type), item.count(),
                     item.large ? " (large)" : "", FormatMetaValue(item, max_values));
  }
  return s;
}

Status FormatPtexFaces(const PtexFile& file, std::string& out) {
  const PtexHeaderInfo& h = file.header();
  const int edges = h.mesh_type == PtexMeshType::kTriangle ? 3 : 4;
  const int nch = h.num_channels;
  std::vector<float> texels, average(static_cast<std::size_t>(nch));
  for (int f = 0; f < h.num_faces; ++f) {
    const PtexFaceInfo& info = file.face_info(PtexFaceId(f));
    std::string line = fmt::format("{} {}x{} {} adj {}", f, info.ures(), info.vres(),
                                   FlagsText(info), AdjacencyText(info, edges));
    file.ConstantValue(PtexFaceId(f), average.data());
    if (info.constant) {
      line += fmt::format(" value {}", fmt::join(average, " "));
    } else {
      DISPEX_RETURN_IF_ERROR(file.ReadFace(PtexFaceId(f), 0, texels));
      std::vector<float> lo(texels.begin(), texels.begin() + nch), hi = lo;
      for (std::size_t i = 0; i < texels.size(); ++i) {
        const std::size_t c = i % std::size_t(nch);
        lo[c] = std::min(lo[c], texels[i]);
        hi[c] = std::max(hi[c], texels[i]);
      }
      line += fmt::format(" min {} max {} avg {}", fmt::join(lo, " "), fmt::join(hi, " "),
                          fmt::join(average, " "));
    }
    out += line;
    out += '\n';
  }
  return Status::Ok();
}

Status FormatPtexTexels(const PtexFile& file, PtexFaceId face, std::string& out) {
  if (face.value < 0 || face.value >= file.num_faces()) {
    return Status::Error(file.name() + ": face " + std::to_string(face.value) + " is not in 0.." +
                         std::to_string(file.num_faces() - 1));
  }
  const PtexHeaderInfo& h = file.header();
  const PtexFaceInfo& info = file.face_info(face);
  std::vector<std::uint8_t> raw;
  DISPEX_RETURN_IF_ERROR(file.ReadFaceRaw(face, 0, raw));
  const std::size_t pixel = std::size_t(h.pixel_size());
  out += fmt::format("face {} {}x{} {} {}\n", face.value, info.ures(), info.vres(),
                     PtexDataTypeName(h.data_type), FlagsText(info));
  for (int v = 0; v < info.vres(); ++v) {
    out += fmt::format("v={}:", v);
    for (int u = 0; u < info.ures(); ++u) {
      out += ' ';
      out += TexelText(raw.data() + (std::size_t(v) * info.ures() + u) * pixel, h.num_channels,
                       h.data_type);
    }
    out += '\n';
  }
  return Status::Ok();
}

Status FormatPtexStructure(const PtexFile& file, std::string& out) {
  const PtexHeaderInfo& h = file.header();
  const int edges = h.mesh_type == PtexMeshType::kTriangle ? 3 : 4;
  out += fmt::format(
      "header: mesh {} data {} channels {} alpha {} faces {} levels {} minor {} borders {} {} "
      "edgefilter {}\n",
      PtexMeshTypeName(h.mesh_type), PtexDataTypeName(h.data_type), h.num_channels, h.alpha_channel,
      h.num_faces, h.num_levels, h.minor_version, PtexBorderModeName(h.u_border),
      PtexBorderModeName(h.v_border), PtexEdgeFilterModeName(h.edge_filter));
  for (int f = 0; f < h.num_faces; ++f) {
    const PtexFaceInfo& info = file.face_info(PtexFaceId(f));
    out += fmt::format(
        "faceinfo {}: log2 ({},{}) flags {} adj {} const {}\n", f, info.ulog2, info.vlog2,
        FlagsText(info), AdjacencyText(info, edges),
        TexelText(file.ConstantValueRaw(PtexFaceId(f)).data(), h.num_channels, h.data_type));
  }
  // Level entries in stored order: level 0 by face id, reductions in reduction order.
  std::vector<std::vector<int>> entries(static_cast<std::size_t>(h.num_levels));
  for (int f = 0; f < h.num_faces; ++f) entries[0].push_back(f);
  {
    std::vector<PtexFaceInfo> infos;
    for (int f = 0; f < h.num_faces; ++f) infos.push_back(file.face_info(PtexFaceId(f)));
    std::vector<std::int32_t> order = ReductionOrder(infos);
    for (int l = 1; l < h.num_levels; ++l) {
      const int n = file.levels()[std::size_t(l)].num_entries;
      for (int r = 0; r < n; ++r) entries[std::size_t(l)].push_back(order[std::size_t(r)]);
    }
  }
  std::vector<std::uint8_t> raw;
  const std::size_t pixel = std::size_t(h.pixel_size());
  for (int l = 0; l < h.num_levels; ++l) {
    out += fmt::format("level {}: {} entries\n", l, entries[std::size_t(l)].size());
    for (int f : entries[std::size_t(l)]) {
      const PtexFaceId id(f);
      if (l >= file.NumStoredLevels(id)) {
        out += fmt::format("  face {}: not read (constant or edited face)\n", f);
        continue;
      }
      const PtexBlockInfo b = file.BlockInfo(id, l);
      out += fmt::format("  face {}: {}x{} {}", f, 1 << b.ulog2, 1 << b.vlog2,
                         file.face_info(id).constant ? "constant-face" : EncodingName(b.encoding));
      if (b.encoding == PtexBlockInfo::Encoding::kTiled) {
        out += fmt::format(" tiles {} of {}x{}", b.num_tiles, 1 << b.tile_ulog2, 1 << b.tile_vlog2);
      }
      out += '\n';
      if (file.face_info(id).constant) continue;
      DISPEX_RETURN_IF_ERROR(file.ReadFaceRaw(id, l, raw));
      const int ures = 1 << b.ulog2;
      for (int v = 0; v < (1 << b.vlog2); ++v) {
        out += fmt::format("    v={}:", v);
        for (int u = 0; u < ures; ++u) {
          out += ' ';
          out += TexelText(raw.data() + (std::size_t(v) * ures + u) * pixel, h.num_channels,
                           h.data_type);
        }
        out += '\n';
      }
    }
  }
  out += fmt::format("meta data: {} items\n", file.meta_data().size());
  for (const PtexMetaItem& item : file.meta_data()) {
    out += fmt::format("  {} {}[{}]{}: {}\n", item.key, PtexMetaTypeName(item.type), item.count(),
                       item.large ? " large" : "", FormatMetaValue(item, item.count()));
  }
  return Status::Ok();
}

}  // namespace dispex
