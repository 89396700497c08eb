// Contract checks for reader results; see reader_contract.h. Written against the public
// headers only, so they test what a caller of the library relies on.
#include "fuzz/reader_contract.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

namespace dispex::fuzz {
namespace {

std::string Num(std::uint64_t v) {
  return std::to_string(v);
}

bool SameFloat(float a, float b) {
  return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}

bool SameTags(const SubdivTags& a, const SubdivTags& b) {
  if (a.creases.size() != b.creases.size() || a.corners.size() != b.corners.size() ||
      a.holes != b.holes || a.boundary != b.boundary ||
      a.boundary_from_file != b.boundary_from_file || a.crease_method != b.crease_method ||
      a.crease_method_from_file != b.crease_method_from_file || a.triangles != b.triangles ||
      a.triangles_from_file != b.triangles_from_file ||
      a.ignored_tag_names != b.ignored_tag_names) {
    return false;
  }
  for (std::size_t i = 0; i < a.creases.size(); ++i) {
    const SubdivTags::Crease &x = a.creases[i], &y = b.creases[i];
    if (x.v0 != y.v0 || x.v1 != y.v1 || !SameFloat(x.sharpness, y.sharpness)) return false;
  }
  for (std::size_t i = 0; i < a.corners.size(); ++i) {
    const SubdivTags::Corner &x = a.corners[i], &y = b.corners[i];
    if (x.vertex != y.vertex || !SameFloat(x.sharpness, y.sharpness)) return false;
  }
  return true;
}

std::string CheckTags(const Mesh& mesh) {
  const auto nv = static_cast<std::int64_t>(mesh.num_vertices());
  const auto nf = static_cast<std::int64_t>(mesh.num_faces());
  auto sharpness_ok = [](float s) { return std::isfinite(s) && s >= 0; };
  for (std::size_t i = 0; i < mesh.tags.creases.size(); ++i) {
    const SubdivTags::Crease& c = mesh.tags.creases[i];
    if (c.v0.value < 0 || c.v0.value >= nv || c.v1.value < 0 || c.v1.value >= nv) {
      return "crease " + Num(i) + " has a vertex id out of range";
    }
    if (!sharpness_ok(c.sharpness)) return "crease " + Num(i) + " has a bad sharpness";
  }
  for (std::size_t i = 0; i < mesh.tags.corners.size(); ++i) {
    const SubdivTags::Corner& c = mesh.tags.corners[i];
    if (c.vertex.value < 0 || c.vertex.value >= nv) {
      return "corner " + Num(i) + " has a vertex id out of range";
    }
    if (!sharpness_ok(c.sharpness)) return "corner " + Num(i) + " has a bad sharpness";
  }
  for (std::size_t i = 0; i < mesh.tags.holes.size(); ++i) {
    const std::int32_t h = mesh.tags.holes[i].value;
    if (h < 0 || h >= nf) return "hole " + Num(i) + " has a face id out of range";
  }
  return {};
}

std::string CheckGroups(const Mesh& mesh) {
  if (mesh.face_groups.empty()) {
    return mesh.group_names.empty() ? std::string() : "group names without face groups";
  }
  if (mesh.face_groups.size() != mesh.num_faces()) {
    return Num(mesh.face_groups.size()) + " face groups for " + Num(mesh.num_faces()) + " faces";
  }
  std::vector<bool> used(mesh.group_names.size(), false);
  for (std::size_t f = 0; f < mesh.face_groups.size(); ++f) {
    const std::int32_t g = mesh.face_groups[f];
    if (g < 0 || static_cast<std::size_t>(g) >= mesh.group_names.size()) {
      return "face " + Num(f) + " has group id " + std::to_string(g) + " of " +
             Num(mesh.group_names.size());
    }
    used[static_cast<std::size_t>(g)] = true;
  }
  for (std::size_t g = 0; g < used.size(); ++g) {
    if (!used[g]) return "group " + Num(g) + " owns no face";
  }
  return {};
}

// Mesh::uvs: both arrays empty, or one in-range index per corner and finite (u, v) pairs; UVs
// dropped (faces_without_uvs > 0) only for some, not all, faces and with both arrays empty.
std::string CheckUvs(const Mesh& mesh) {
  if (mesh.uvs.size() % 2 != 0) return "uvs holds an odd number of floats";
  if (mesh.face_uv_indices.empty()) {
    if (!mesh.uvs.empty()) return "uvs without face_uv_indices";
  } else {
    if (mesh.face_uv_indices.size() != mesh.face_indices.size()) {
      return Num(mesh.face_uv_indices.size()) + " face uv indices for " +
             Num(mesh.face_indices.size()) + " face corners";
    }
    const auto nuv = static_cast<std::int64_t>(mesh.uvs.size() / 2);
    for (std::size_t i = 0; i < mesh.face_uv_indices.size(); ++i) {
      if (mesh.face_uv_indices[i] < 0 || mesh.face_uv_indices[i] >= nuv) {
        return "face uv index " + std::to_string(mesh.face_uv_indices[i]) + " at corner " + Num(i) +
               " out of range (" + Num(mesh.uvs.size() / 2) + " uvs)";
      }
    }
    if (mesh.faces_without_uvs != 0) return "faces_without_uvs set while UVs are kept";
  }
  for (std::size_t i = 0; i < mesh.uvs.size(); ++i) {
    if (!std::isfinite(mesh.uvs[i])) return "uv " + Num(i / 2) + " is not finite";
  }
  if (mesh.faces_without_uvs >= mesh.num_faces() && mesh.faces_without_uvs != 0) {
    return "faces_without_uvs " + Num(mesh.faces_without_uvs) + " is not fewer than the " +
           Num(mesh.num_faces()) + " faces";
  }
  return {};
}

// The measures a caller runs right after reading must accept any mesh a reader returns.
std::string CheckMeasures(const Mesh& mesh) {
  const MeshValidation v = ValidateMesh(mesh);
  if (v.unreferenced_vertices > mesh.num_vertices() || v.degenerate_faces > mesh.num_faces() ||
      v.boundary_edges > mesh.face_indices.size() ||
      v.non_manifold_edges > mesh.face_indices.size() ||
      v.inconsistent_edges > mesh.face_indices.size()) {
    return "ValidateMesh counts exceed the mesh's size";
  }
  const std::size_t kinds =
      std::size_t{v.unreferenced_vertices > 0} + std::size_t{v.degenerate_faces > 0} +
      std::size_t{v.non_manifold_edges > 0} + std::size_t{v.inconsistent_edges > 0};
  if (v.warnings.size() != kinds) {
    return "ValidateMesh gave " + Num(v.warnings.size()) + " warnings for " + Num(kinds) +
           " kinds of problem";
  }
  const Status clean = RequireClean(mesh, v);
  if (clean.ok() != v.clean()) return "RequireClean disagrees with MeshValidation::clean()";
  if (!clean.ok()) {
    if (std::string why = CheckErrorMessage(clean, mesh.source); !why.empty()) {
      return "RequireClean: " + why;
    }
  }
  const BoundingBox box = ComputeBounds(mesh);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Float3& p = mesh.positions[i];
    if (p.x < box.min.x || p.y < box.min.y || p.z < box.min.z || p.x > box.max.x ||
        p.y > box.max.y || p.z > box.max.z) {
      return "ComputeBounds: vertex " + Num(i) + " lies outside the box";
    }
  }
  const double median = MedianEdgeLength(mesh);
  if (std::isnan(median) || median < 0) return "MedianEdgeLength is NaN or negative";
  return {};
}

}  // namespace

std::string CheckErrorMessage(const Status& status, const std::string& name) {
  if (status.ok()) return "expected a failed Status";
  const std::string& m = status.message();
  for (const char c : m) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) {
      std::string shown;  // the message with its control bytes visible, for the report
      for (const char d : m) {
        const auto b = static_cast<unsigned char>(d);
        char hex[8];
        std::snprintf(hex, sizeof hex, "\\x%02x", b);
        shown += b < 0x20 || b == 0x7f ? std::string(hex) : std::string(1, d);
      }
      return "error message has a control byte (not one printable line): \"" + shown + "\"";
    }
  }
  if (m.size() <= name.size() + 1 || m.compare(0, name.size(), name) != 0 ||
      m[name.size()] != ':') {
    return "error message does not start with \"" + name + ":\": \"" + m + "\"";
  }
  return {};
}

std::string CheckMeshResult(const StatusOr<Mesh>& result, const std::string& name) {
  return result.ok() ? CheckMesh(*result, name) : CheckErrorMessage(result.status(), name);
}

std::string CheckMesh(const Mesh& mesh, const std::string& name) {
  if (mesh.source != name) return "source is \"" + mesh.source + "\", not \"" + name + "\"";
  if (mesh.num_faces() == 0) return "a mesh without faces";
  if (mesh.face_offsets.front() != 0) return "face_offsets does not start at 0";
  if (mesh.face_offsets.back() != mesh.face_indices.size()) {
    return "face_offsets ends at " + Num(mesh.face_offsets.back()) + ", face_indices has " +
           Num(mesh.face_indices.size());
  }
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    if (mesh.face_offsets[f + 1] < mesh.face_offsets[f] + 3) {
      return "face " + Num(f) + " has fewer than 3 corners (or offsets decrease)";
    }
  }
  const auto nv = static_cast<std::int64_t>(mesh.num_vertices());
  for (std::size_t i = 0; i < mesh.face_indices.size(); ++i) {
    if (mesh.face_indices[i] < 0 || mesh.face_indices[i] >= nv) {
      return "face index " + std::to_string(mesh.face_indices[i]) + " at corner " + Num(i) +
             " out of range (" + Num(mesh.num_vertices()) + " vertices)";
    }
  }
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Float3& p = mesh.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return "vertex " + Num(i) + " is not finite";
    }
  }
  if (mesh.positions.capacity() <= mesh.positions.size()) {
    return "positions has no spare capacity (Embree reads past the last vertex)";
  }
  if (std::string why = CheckGroups(mesh); !why.empty()) return why;
  if (std::string why = CheckTags(mesh); !why.empty()) return why;
  if (std::string why = CheckUvs(mesh); !why.empty()) return why;
  return CheckMeasures(mesh);
}

std::string CompareMeshResults(const StatusOr<Mesh>& a, const StatusOr<Mesh>& b) {
  if (a.ok() != b.ok()) {
    return "one read failed and the other did not: \"" +
           (a.ok() ? b.status().message() : a.status().message()) + "\"";
  }
  if (!a.ok()) {
    if (a.status().message() != b.status().message()) {
      return "different errors: \"" + a.status().message() + "\" vs \"" + b.status().message() +
             "\"";
    }
    return {};
  }
  const Mesh &x = *a, &y = *b;
  if (x.positions.size() != y.positions.size() ||
      (!x.positions.empty() && std::memcmp(x.positions.data(), y.positions.data(),
                                           x.positions.size() * sizeof(Float3)) != 0)) {
    return "different positions";
  }
  if (x.face_offsets != y.face_offsets || x.face_indices != y.face_indices) {
    return "different faces";
  }
  if (x.face_groups != y.face_groups || x.group_names != y.group_names) {
    return "different groups";
  }
  if (!SameTags(x.tags, y.tags)) return "different tags";
  if (x.uvs.size() != y.uvs.size() ||
      (!x.uvs.empty() &&
       std::memcmp(x.uvs.data(), y.uvs.data(), x.uvs.size() * sizeof(float)) != 0) ||
      x.face_uv_indices != y.face_uv_indices || x.faces_without_uvs != y.faces_without_uvs) {
    return "different uvs";
  }
  return {};
}

std::string ExercisePtex(std::string_view bytes, const std::string& name,
                         const PtexExerciseLimits& limits) {
  PtexReadOptions options;
  options.max_values_per_read = limits.max_values_per_read;
  const StatusOr<PtexFile> opened = ParsePtex(bytes, name, options);
  if (!opened.ok()) return CheckErrorMessage(opened.status(), name);
  const PtexFile& file = *opened;
  const PtexHeaderInfo& header = file.header();
  const int nfaces = file.num_faces();
  const int nch = header.num_channels;
  if (file.name() != name) return "name() is \"" + file.name() + "\"";
  if (nfaces < 1 || nfaces != header.num_faces) return "bad face count " + Num(nfaces);
  if (nch < 1 || header.alpha_channel < -1 || header.alpha_channel >= nch) {
    return "bad channel count or alpha channel";
  }
  if (header.num_levels < 1 || file.levels().size() != std::size_t(header.num_levels)) {
    return "levels() has " + Num(file.levels().size()) + " entries, the header says " +
           std::to_string(header.num_levels);
  }
  if (header.file_size != bytes.size()) return "file_size differs from the input's size";
  const std::size_t value_size = std::size_t(PtexDataSize(header.data_type));

  auto failed = [&](const Status& s, const std::string& what) {
    const std::string why = CheckErrorMessage(s, name);
    return why.empty() ? why : what + ": " + why;
  };

  // First pass: records, levels and block infos, which cost nothing to read.
  std::size_t planned = 0;  // values that reading every stored level of every face decodes
  for (int f = 0; f < nfaces; ++f) {
    const PtexFaceId id(f);
    const PtexFaceInfo& info = file.face_info(id);
    const std::string where = "face " + std::to_string(f);
    if (info.ulog2 < 0 || info.ulog2 > 15 || info.vlog2 < 0 || info.vlog2 > 15) {
      return where + ": resolution log2 out of 0..15";
    }
    if (header.mesh_type == PtexMeshType::kTriangle && info.ulog2 != info.vlog2) {
      return where + ": non-square triangle face";
    }
    for (int e = 0; e < 4; ++e) {
      if (info.adjfaces[std::size_t(e)] < -1 || info.adjfaces[std::size_t(e)] >= nfaces) {
        return where + ": neighbour out of range";
      }
    }
    const int stored = file.NumStoredLevels(id);
    if (stored < 1 || stored > header.num_levels) return where + ": bad stored level count";
    if (stored > 1 && stored - 1 > std::min(info.ulog2, info.vlog2)) {
      return where + ": more stored levels than the resolution allows";
    }
    if (info.constant && stored != 1) return where + ": constant face with reductions";
    if (file.ConstantValueRaw(id).size() != std::size_t(header.pixel_size())) {
      return where + ": constant value of the wrong size";
    }
    std::vector<float> value(static_cast<std::size_t>(nch));
    file.ConstantValue(id, value.data());
    for (int l = 0; l < stored; ++l) {
      const PtexBlockInfo block = file.BlockInfo(id, l);
      if (block.ulog2 != info.ulog2 - l || block.vlog2 != info.vlog2 - l) {
        return where + " level " + std::to_string(l) + ": block resolution disagrees";
      }
      if (block.num_tiles < 1 || block.tile_ulog2 > block.ulog2 || block.tile_vlog2 > block.vlog2 ||
          block.tile_ulog2 < 0 || block.tile_vlog2 < 0) {
        return where + " level " + std::to_string(l) + ": bad tiling";
      }
      const std::size_t count = (info.num_texels() >> (2 * l)) * std::size_t(nch);
      if (!info.constant && count <= limits.max_values_per_read) planned += count;
    }
  }

  // Second pass: decode within the budget.
  std::size_t spent = 0;
  bool all_read = true, any_failed = false;
  std::vector<float> texels;
  std::vector<std::uint8_t> raw;
  for (int f = 0; f < nfaces && all_read; ++f) {
    const PtexFaceId id(f);
    const PtexFaceInfo& info = file.face_info(id);
    const std::string where = "face " + std::to_string(f);
    bool level0_ok = false;
    std::vector<float> level0;
    for (int l = 0; l < file.NumStoredLevels(id); ++l) {
      const std::size_t count = (info.num_texels() >> (2 * l)) * std::size_t(nch);
      // Reads over the reader's limit must fail, at once (they cost nothing).
      const bool over_limit = count > limits.max_values_per_read;
      if (!over_limit) {
        if (spent + 2 * count > limits.value_budget) {
          all_read = false;
          break;
        }
        spent += 2 * count;
      }
      const std::string at = where + " level " + std::to_string(l);
      const Status s = file.ReadFace(id, l, texels);
      const Status sr = file.ReadFaceRaw(id, l, raw);
      if (s.ok() != sr.ok()) return at + ": ReadFace and ReadFaceRaw disagree";
      if (over_limit && s.ok()) return at + ": a read over max_values_per_read succeeded";
      if (!s.ok()) {
        if (info.constant && !over_limit) {
          return at + ": a constant face failed to read: " + s.message();
        }
        if (std::string why = failed(s, at); !why.empty()) return why;
        any_failed = any_failed || !info.constant;  // Validate skips constant faces
        continue;
      }
      if (texels.size() != count) {
        return at + ": ReadFace gave " + Num(texels.size()) + " values, expected " + Num(count);
      }
      if (raw.size() != count * value_size) return at + ": ReadFaceRaw has the wrong size";
      if (l == 0) {
        level0_ok = true;
        level0 = texels;
      }
    }
    if (!all_read) break;
    // Sample decodes level 0 again (into its cache).
    const std::size_t count0 = info.num_texels() * std::size_t(nch);
    if (count0 <= limits.max_values_per_read) {
      if (spent + count0 > limits.value_budget) {
        all_read = false;
        break;
      }
      spent += count0;
    }
    const int ures = info.ures(), vres = info.vres();
    const float points[][2] = {{0.f, 0.f}, {1.f, 1.f},     {0.5f, 0.5f}, {1.f, 0.f},
                               {0.f, 1.f}, {0.25f, 0.75f}, {0.9f, 0.05f}};
    for (int c : {0, nch - 1}) {
      for (const auto& p : points) {
        const float sample = file.Sample(id, p[0], p[1], c);
        if (!info.constant && !level0_ok && !std::isnan(sample)) {
          return where + ": Sample of an undecodable face is not NaN";
        }
      }
      if (!level0_ok || info.constant || header.mesh_type != PtexMeshType::kQuad) continue;
      // At a texel centre the bilinear weights are exactly 0 and 1 (power-of-two
      // resolutions), so Sample returns the texel itself.
      const int is[] = {0, ures / 2, ures - 1}, js[] = {0, vres / 2, vres - 1};
      for (int i : is) {
        for (int j : js) {
          const int i1 = std::min(i + 1, ures - 1), j1 = std::min(j + 1, vres - 1);
          auto at = [&](int x, int y) {
            return level0[(std::size_t(y) * std::size_t(ures) + std::size_t(x)) * std::size_t(nch) +
                          std::size_t(c)];
          };
          // The weight-0 terms vanish only where the differences are finite.
          if (!std::isfinite(at(i1, j) - at(i, j)) || !std::isfinite(at(i1, j1) - at(i, j1)) ||
              !std::isfinite(at(i, j1) - at(i, j))) {
            continue;
          }
          const float u = (float(i) + 0.5f) / float(ures), v = (float(j) + 0.5f) / float(vres);
          const float sample = file.Sample(id, u, v, c);
          if (!SameFloat(sample, at(i, j)) && !(sample == 0 && at(i, j) == 0)) {
            return where + ": Sample at the centre of texel (" + std::to_string(i) + ", " +
                   std::to_string(j) + ") is not the texel";
          }
        }
      }
    }
  }
  file.ReleaseSampleCache();

  if (all_read && planned <= limits.value_budget) {
    const Status v = file.Validate();
    if (v.ok() == any_failed) {
      return std::string("Validate ") + (v.ok() ? "passed" : "failed") + " but face reads " +
             (any_failed ? "failed" : "all passed");
    }
    if (!v.ok()) {
      if (std::string why = failed(v, "Validate"); !why.empty()) return why;
    }
  }

  for (const PtexMetaItem& item : file.meta_data()) {
    const std::string where = "meta data '" + item.key + "'";
    const PtexMetaItem* found = file.FindMetaData(item.key);
    if (found == nullptr || found->key != item.key) return where + ": FindMetaData misses it";
    const std::size_t n = item.count();
    const std::size_t numbers = item.AsNumbers().size();
    std::size_t typed = 0;
    switch (item.type) {
      case PtexMetaType::kString:
        (void)item.AsString();
        typed = 1;
        if (numbers != 0) return where + ": a string gave numbers";
        break;
      case PtexMetaType::kInt8:
        typed = item.AsInt8().size();
        break;
      case PtexMetaType::kInt16:
        typed = item.AsInt16().size();
        break;
      case PtexMetaType::kInt32:
        typed = item.AsInt32().size();
        break;
      case PtexMetaType::kFloat:
        typed = item.AsFloat().size();
        break;
      case PtexMetaType::kDouble:
        typed = item.AsDouble().size();
        break;
    }
    if (typed != n) return where + ": count() " + Num(n) + " but " + Num(typed) + " values";
    if (item.type != PtexMetaType::kString && numbers != n) {
      return where + ": AsNumbers gave " + Num(numbers) + " values";
    }
  }
  return {};
}

}  // namespace dispex::fuzz
