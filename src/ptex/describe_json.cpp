// PtexSummaryJson: the summary `dispex info --json` prints for a Ptex file (and HasPtexMagic,
// which tells it from a mesh).
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dispex/ptex_describe.h"

namespace dispex {

namespace {

constexpr std::size_t kMaxJsonValues = 64;

nlohmann::json MetaJson(const PtexMetaItem& item) {
  nlohmann::json j;
  j["key"] = item.key;
  j["type"] = std::string(PtexMetaTypeName(item.type));
  j["count"] = item.count();
  j["large"] = item.large;
  if (item.type == PtexMetaType::kString) {
    j["value"] = item.AsString();
  } else {
    std::vector<double> values = item.AsNumbers();
    j["truncated"] = values.size() > kMaxJsonValues;
    if (values.size() > kMaxJsonValues) values.resize(kMaxJsonValues);
    j["value"] = values;
  }
  return j;
}

nlohmann::json SummaryObject(const PtexFile& file, bool with_faces) {
  const PtexHeaderInfo& h = file.header();
  nlohmann::json j;
  j["file"] = file.name();
  j["size_bytes"] = h.file_size;
  j["minor_version"] = h.minor_version;
  j["mesh_type"] = std::string(PtexMeshTypeName(h.mesh_type));
  j["data_type"] = std::string(PtexDataTypeName(h.data_type));
  j["channels"] = h.num_channels;
  j["alpha_channel"] = h.alpha_channel;
  j["faces"] = h.num_faces;
  std::size_t constant = 0, subfaces = 0, texels0 = 0, texels_reduced = 0;
  for (int f = 0; f < h.num_faces; ++f) {
    const PtexFaceInfo& info = file.face_info(PtexFaceId(f));
    constant += info.constant;
    subfaces += info.subface;
    if (info.constant) continue;
    texels0 += info.num_texels();
    for (int l = 1; l < file.NumStoredLevels(PtexFaceId(f)); ++l) {
      texels_reduced += info.num_texels() >> (2 * l);
    }
  }
  j["constant_faces"] = constant;
  j["subfaces"] = subfaces;
  nlohmann::json levels = nlohmann::json::array();
  for (const PtexLevelInfo& l : file.levels()) levels.push_back(l.num_entries);
  j["level_entries"] = levels;
  j["u_border"] = std::string(PtexBorderModeName(h.u_border));
  j["v_border"] = std::string(PtexBorderModeName(h.v_border));
  j["edge_filter"] = std::string(PtexEdgeFilterModeName(h.edge_filter));
  j["texels_level0"] = texels0;
  j["texels_reductions"] = texels_reduced;
  j["has_edits"] = h.has_edits;
  nlohmann::json meta = nlohmann::json::array();
  for (const PtexMetaItem& item : file.meta_data()) meta.push_back(MetaJson(item));
  j["meta_data"] = meta;
  if (with_faces) {
    nlohmann::json faces = nlohmann::json::array();
    std::vector<float> value(static_cast<std::size_t>(h.num_channels));
    for (int f = 0; f < h.num_faces; ++f) {
      const PtexFaceInfo& info = file.face_info(PtexFaceId(f));
      file.ConstantValue(PtexFaceId(f), value.data());
      nlohmann::json face;
      face["id"] = f;
      face["ulog2"] = info.ulog2;
      face["vlog2"] = info.vlog2;
      face["constant"] = info.constant;
      face["subface"] = info.subface;
      face["adjfaces"] = info.adjfaces;
      face["adjedges"] = info.adjedges;
      face["average"] = value;
      faces.push_back(face);
    }
    j["face_list"] = faces;
  }
  return j;
}

}  // namespace

bool HasPtexMagic(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);
  return in.gcount() == 4 && magic[0] == 'P' && magic[1] == 't' && magic[2] == 'e' &&
         magic[3] == 'x';
}

std::string PtexSummaryJson(const PtexFile& file, bool with_faces) {
  return SummaryObject(file, with_faces).dump(2);
}

}  // namespace dispex
