#include "view/map_source.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "dispex/vector_space.h"

namespace dispex::view {

namespace {

std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

// ---- How the map displaces ------------------------------------------------------------------

// D's normal part.
float NormalPart(const float* d, const float* n) {
  return d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
}

// A scalar Ptex map read as the reference Ptex filter reads it, across face edges: P + h N.
class PtexScalarDisplacement final : public view::MapDisplacement {
 public:
  explicit PtexScalarDisplacement(const PtexMapSampler& sampler) : sampler_(sampler) {}
  void Displace(PtexFaceId face, std::span<const float> uv, const LimitEvaluator::Frames& frames,
                std::span<float> d, std::span<float> value) const override {
    for (std::size_t j = 0; j < value.size(); ++j) {
      const float h =
          static_cast<float>(sampler_.SampleAcrossFaces(face, uv[2 * j], uv[2 * j + 1]));
      for (std::size_t c = 0; c < 3; ++c) d[3 * j + c] = h * frames.normals[3 * j + c];
      value[j] = h;
    }
  }

 private:
  const PtexMapSampler& sampler_;
};

// A vector Ptex map, each face read on its own (bilinear, clamped at its border) in its frame.
class PtexVectorDisplacement final : public view::MapDisplacement {
 public:
  PtexVectorDisplacement(const PtexFile& map, VectorSpace space) : map_(map), space_(space) {}
  void Displace(PtexFaceId face, std::span<const float> uv, const LimitEvaluator::Frames& frames,
                std::span<float> d, std::span<float> value) const override {
    for (std::size_t j = 0; j < value.size(); ++j) {
      const float u = uv[2 * j], v = uv[2 * j + 1];
      const float c[3] = {map_.Sample(face, u, v, 0), map_.Sample(face, u, v, 1),
                          map_.Sample(face, u, v, 2)};
      const SurfaceFrame frame = Frame(frames, j);
      const Float3 vec = VectorFromChannels(space_, frame, c);
      d[3 * j] = vec.x, d[3 * j + 1] = vec.y, d[3 * j + 2] = vec.z;
      value[j] = NormalPart(&d[3 * j], &frames.normals[3 * j]);
    }
  }
  static SurfaceFrame Frame(const LimitEvaluator::Frames& f, std::size_t j) {
    return {{f.du[3 * j], f.du[3 * j + 1], f.du[3 * j + 2]},
            {f.dv[3 * j], f.dv[3 * j + 1], f.dv[3 * j + 2]},
            {f.normals[3 * j], f.normals[3 * j + 1], f.normals[3 * j + 2]}};
  }

 private:
  const PtexFile& map_;
  VectorSpace space_;
};

// A UV-space map through the cage's UVs, bilinear within its UDIM tile: a scalar along the
// normal, or an object-space vector.
class UvDisplacement final : public view::MapDisplacement {
 public:
  UvDisplacement(const UvMap& map, const PtexUvCharts& charts, bool vector,
                 std::vector<std::atomic<std::uint8_t>>& missing)
      : map_(map), charts_(charts), vector_(vector), missing_(missing) {}
  void Displace(PtexFaceId face, std::span<const float> uv, const LimitEvaluator::Frames& frames,
                std::span<float> d, std::span<float> value) const override {
    for (std::size_t j = 0; j < value.size(); ++j) {
      double at[2];
      charts_.Evaluate(face, uv[2 * j], uv[2 * j + 1], at);
      float c[3] = {0, 0, 0};
      if (!map_.Sample(at[0], at[1], {c, vector_ ? 3u : 1u})) {
        missing_[static_cast<std::size_t>(face.value)].store(1, std::memory_order_relaxed);
      }
      const float* n = &frames.normals[3 * j];
      if (vector_) {
        for (std::size_t k = 0; k < 3; ++k) d[3 * j + k] = c[k];
        value[j] = NormalPart(c, n);
      } else {
        for (std::size_t k = 0; k < 3; ++k) d[3 * j + k] = c[0] * n[k];
        value[j] = c[0];
      }
    }
  }

 private:
  const UvMap& map_;
  const PtexUvCharts& charts_;
  bool vector_;
  std::vector<std::atomic<std::uint8_t>>& missing_;
};

// ---- Inputs ---------------------------------------------------------------------------------

// The map's dispex:* meta data as JSON: strings (options and statistics parsed), short numeric
// arrays, the discontinuous faces; the incremental records are left out (binary, large).
json MetaJson(const PtexFile& map) {
  json meta = json::object();
  for (const PtexMetaItem& item : map.meta_data()) {
    if (item.key.rfind("dispex:", 0) != 0) continue;
    if (item.key == "dispex:face_keys" || item.key.find("records") != std::string::npos ||
        item.key == "dispex:inputs_key") {
      continue;
    }
    if (item.type == PtexMetaType::kString) {
      const std::string text = item.AsString();
      if (item.key == "dispex:options" || item.key == "dispex:statistics") {
        json parsed = json::parse(text, nullptr, false);
        if (!parsed.is_discarded()) {
          meta[item.key] = std::move(parsed);
          continue;
        }
      }
      meta[item.key] = text;
      continue;
    }
    const std::vector<double> numbers = item.AsNumbers();
    if (item.key == "dispex:discontinuous_faces") {
      meta[item.key] = numbers;
    } else if (numbers.size() == 1) {
      meta[item.key] = numbers[0];
    } else if (numbers.size() <= 64) {
      meta[item.key] = numbers;
    }
  }
  return meta;
}

// A UV-space map (tiles), read through the cage's UVs.
Status ReadUvMap(const ViewPageOptions& options, const Mesh& base, const LimitSurface& surface,
                 ViewPageReport& report, MapSource& map) {
  const int num_faces = surface.num_ptex_faces();
  DISPEX_ASSIGN_OR_RETURN(map.uv, UvMap::Open(options.map_path));
  const UvMap& uv = *map.uv;
  const bool vector = uv.channels() == 3;
  if (vector) {
    const std::string space = uv.Attribute("dispex:space");
    if (!space.empty() && space != "object") {
      return Status::Error(StatusCode::kBadInput,
                           fmt::format("{}: 3 channels in dispex:space '{}': UV-space vector "
                                       "maps are read in object space",
                                       options.map_path, space));
    }
  }
  DISPEX_ASSIGN_OR_RETURN(map.charts, PtexUvCharts::Build(base, surface));
  map.uv_missing = std::vector<std::atomic<std::uint8_t>>(static_cast<std::size_t>(num_faces));
  map.displacement = std::make_unique<UvDisplacement>(uv, *map.charts, vector, map.uv_missing);
  report.map_kind = vector ? "uv vector" : "uv scalar";
  if (vector) report.vector_space = "object";
  json meta = json::object();
  for (const auto& [key, value] : uv.tiles().front().attributes) {
    if (key.rfind("dispex:", 0) == 0) meta[key] = value;
  }
  json tiles = json::array();
  for (std::size_t t = 0; t < uv.tiles().size(); ++t) {
    tiles.push_back({{"udim", uv.tiles()[t].udim}, {"path", FileName(uv.paths()[t])}});
  }
  const std::string tau = uv.Attribute("dispex:tolerance");
  if (!tau.empty()) map.tolerance = std::strtod(tau.c_str(), nullptr);
  map.map_json = {{"kind", report.map_kind},
                  {"space", vector ? json("object") : json()},
                  {"faces", num_faces},
                  {"channels", uv.channels()},
                  {"resolution", uv.resolution()},
                  {"tiles", tiles},
                  {"meta", meta}};
  return Status::Ok();
}

// A scalar Ptex map's texels, every face's (one for a constant face).
Status ReadScalarTexels(const PtexFile& ptex, std::vector<std::vector<float>>& texels) {
  texels.resize(static_cast<std::size_t>(ptex.num_faces()));
  for (int f = 0; f < ptex.num_faces(); ++f) {
    const PtexFaceId face(f);
    std::vector<float>& t = texels[static_cast<std::size_t>(f)];
    if (ptex.BlockInfo(face, 0).encoding == PtexBlockInfo::Encoding::kConstant) {
      t.resize(1);
      ptex.ConstantValue(face, t.data());
    } else {
      DISPEX_RETURN_IF_ERROR(ptex.ReadFace(face, 0, t));
    }
  }
  return Status::Ok();
}

// A Ptex map, scalar or vector; `faces` takes its resolutions.
Status ReadPtexMap(const ViewPageOptions& options, int num_faces, std::vector<PtexFaceInfo>& faces,
                   ViewPageReport& report, MapSource& map) {
  DISPEX_ASSIGN_OR_RETURN(map.ptex, PtexFile::Open(options.map_path));
  const PtexFile& ptex = *map.ptex;
  if (ptex.num_faces() != num_faces) {
    return Status::Error(
               StatusCode::kMismatch,
               fmt::format("{}: {} faces, but {} has {} Ptex faces: not a map of "
                           "this base mesh",
                           options.map_path, ptex.num_faces(), options.base_path, num_faces))
        .WithPath(options.map_path);
  }
  const PtexMetaItem* space_item = ptex.FindMetaData(kVectorSpaceMetaKey);
  const PtexMetaItem* names_item = ptex.FindMetaData(kVectorChannelsMetaKey);
  const std::string space_value = space_item ? space_item->AsString() : "";
  const std::string names_value = names_item ? names_item->AsString() : "";
  DISPEX_ASSIGN_OR_RETURN(
      const std::optional<VectorSpace> space,
      DisplacementMapSpace(ptex.name(), ptex.header().num_channels, ptex.header().alpha_channel,
                           space_item ? &space_value : nullptr,
                           names_item ? &names_value : nullptr));
  for (int f = 0; f < num_faces; ++f) {
    const PtexFaceInfo& stored = ptex.face_info(PtexFaceId(f));
    faces[static_cast<std::size_t>(f)].ulog2 = stored.ulog2;
    faces[static_cast<std::size_t>(f)].vlog2 = stored.vlog2;
  }
  if (space) {
    map.displacement = std::make_unique<PtexVectorDisplacement>(ptex, *space);
    report.map_kind = "vector";
    report.vector_space = std::string(VectorSpaceName(*space));
  } else {
    DISPEX_RETURN_IF_ERROR(ReadScalarTexels(ptex, map.texels));
    map.sampler.emplace(faces, map.texels);
    map.displacement = std::make_unique<PtexScalarDisplacement>(*map.sampler);
    report.map_kind = "scalar";
  }
  json meta = MetaJson(ptex);
  if (meta.contains("dispex:statistics")) map.statistics = meta["dispex:statistics"];
  if (meta.contains("dispex:tolerance") && meta["dispex:tolerance"].is_number()) {
    map.tolerance = meta["dispex:tolerance"].get<double>();
  }
  map.map_json = {{"kind", report.map_kind},
                  {"space", space ? json(report.vector_space) : json()},
                  {"faces", num_faces},
                  {"channels", ptex.header().num_channels},
                  {"data_type", std::string(PtexDataTypeName(ptex.header().data_type))},
                  {"edge_filter", std::string(PtexEdgeFilterModeName(ptex.header().edge_filter))},
                  {"file_bytes", ptex.header().file_size},
                  {"meta", meta}};
  return Status::Ok();
}

}  // namespace

Status ReadMap(const ViewPageOptions& options, const Mesh& base, const LimitSurface& surface,
               std::vector<PtexFaceInfo>& faces, ViewPageReport& report, MapSource& map) {
  if (IsUvMapPath(options.map_path)) {
    DISPEX_RETURN_IF_ERROR(ReadUvMap(options, base, surface, report, map));
  } else {
    DISPEX_RETURN_IF_ERROR(ReadPtexMap(options, surface.num_ptex_faces(), faces, report, map));
  }
  map.map_json["tolerance"] = map.tolerance > 0 ? json(map.tolerance) : json();
  return Status::Ok();
}

}  // namespace dispex::view
