// dispex render: the base limit surface (displaced by a map or not) and any mesh, ray-cast from
// a camera framed on the base, and the side-by-side comparison. The flow, top-down:
// options -> limit surface -> per-face density -> welded displaced tessellation (with vertex
// normals) -> Embree tracer -> rows of camera rays -> shaded pixels.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "core/parallel.h"
#include "dispex/render.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "dispex/vector_space.h"
#include "render/bitmap_font.h"
#include "render/image_ops.h"
#include "render/ray_caster.h"
#include "render/tessellation.h"

namespace dispex {

namespace {

constexpr render::Rgb kLabel = {235, 235, 235};

}  // namespace

Status ValidateSurfaceRenderOptions(const SurfaceRenderOptions& o) {
  if (o.width < 1 || o.width > 16384 || o.height < 1 || o.height > 16384) {
    return Status::Error(
        fmt::format("width x height = {}x{}: each must be 1..16384", o.width, o.height));
  }
  if (o.density < 1 || o.density > 256) {
    return Status::Error(fmt::format("density = {}: must be 1..256", o.density));
  }
  if (o.min_density < 1 || o.min_density > 256) {
    return Status::Error(fmt::format("min_density = {}: must be 1..256", o.min_density));
  }
  if (o.max_density < o.min_density || o.max_density > 256) {
    return Status::Error(fmt::format("max_density = {}: must be {}..256 (at least min_density)",
                                     o.max_density, o.min_density));
  }
  if (o.supersample < 1 || o.supersample > 4) {
    return Status::Error(fmt::format("supersample = {}: must be 1..4", o.supersample));
  }
  if (o.ao_samples < 0 || o.ao_samples > 64) {
    return Status::Error(fmt::format("ao_samples = {}: must be 0..64 rays", o.ao_samples));
  }
  if (!(o.ao_distance > 0 && o.ao_distance <= 1)) {
    return Status::Error(fmt::format("ao_distance = {}: must be in (0, 1]", o.ao_distance));
  }
  if (o.channel < -1) {
    return Status::Error(
        fmt::format("channel = {}: must be >= 0, or -1 (the map says what it holds)", o.channel));
  }
  if (o.threads < 0) return Status::Error(fmt::format("threads = {}: must be >= 0", o.threads));
  // The view: framing a unit box checks the angles, field of view and margin.
  BoundingBox unit;
  unit.max = {1, 1, 1};
  auto camera = FrameCamera(unit, o.view, 1, 1);
  return camera.ok() ? Status::Ok() : camera.status();
}

namespace {

// How the map displaces (SurfaceRenderOptions::channel): the channel of a scalar map, or a
// vector map's space.
struct MapUse {
  int channel = 0;
  std::optional<VectorSpace> space;
};

StatusOr<MapUse> CheckMap(const Mesh& base, const LimitSurface& surface, const PtexFile& map,
                          int channel) {
  if (map.header().mesh_type != PtexMeshType::kQuad) {
    return Status::Error(map.name() +
                         ": triangle-mesh Ptex files cannot displace a "
                         "Catmull-Clark surface");
  }
  if (channel >= map.header().num_channels) {
    return Status::Error(fmt::format("{}: channel {} out of range (the file has {})", map.name(),
                                     channel, map.header().num_channels));
  }
  if (map.num_faces() != surface.num_ptex_faces()) {
    return Status::Error(fmt::format(
        "{}: {} Ptex faces, but the base mesh {} has {}: the map was made for another mesh",
        map.name(), map.num_faces(), base.source, surface.num_ptex_faces()));
  }
  MapUse use;
  if (channel >= 0) {
    use.channel = channel;
    return use;
  }
  const PtexMetaItem* space = map.FindMetaData(kVectorSpaceMetaKey);
  const PtexMetaItem* names = map.FindMetaData(kVectorChannelsMetaKey);
  const std::string space_value = space ? space->AsString() : "";
  const std::string names_value = names ? names->AsString() : "";
  DISPEX_ASSIGN_OR_RETURN(
      use.space,
      DisplacementMapSpace(map.name(), map.header().num_channels, map.header().alpha_channel,
                           space ? &space_value : nullptr, names ? &names_value : nullptr));
  return use;
}

std::vector<std::array<int, 2>> Densities(const LimitSurface& surface, const PtexFile* map,
                                          const SurfaceRenderOptions& o) {
  std::vector<std::array<int, 2>> density(static_cast<std::size_t>(surface.num_ptex_faces()));
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    if (map == nullptr) {
      density[static_cast<std::size_t>(f)] = {o.density, o.density};
    } else {
      const PtexFaceInfo& info = map->face_info(PtexFaceId(f));
      density[static_cast<std::size_t>(f)] = {
          std::clamp(info.ures(), o.min_density, o.max_density),
          std::clamp(info.vres(), o.min_density, o.max_density)};
    }
  }
  return density;
}

render::ShadingOptions Shading(const SurfaceRenderOptions& o, std::span<const Float3> frame) {
  Float3 lo = frame.empty() ? Float3{} : frame[0], hi = lo;
  for (const Float3& p : frame) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const double diagonal = std::hypot(double(hi.x) - lo.x, double(hi.y) - lo.y, double(hi.z) - lo.z);
  render::ShadingOptions s;
  s.supersample = o.supersample;
  s.ao_samples = o.ao_samples;
  s.ao_distance = static_cast<float>(o.ao_distance * std::max(diagonal, 1e-30));
  return s;
}

// Casts `mesh` into a width x height panel framed on the points `frame`.
StatusOr<Image> Cast(const render::ShadedMesh& mesh, std::span<const Float3> frame,
                     const SurfaceRenderOptions& o, int width, int height) {
  DISPEX_ASSIGN_OR_RETURN(Camera camera, FrameCamera(frame, o.view, width, height));
  if (mesh.mesh.num_faces() == 0) return Image(width, height, render::kPanelBackground);
  TracerOptions tracer_options;
  tracer_options.normal_queries = false;  // camera rays only
  DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<Tracer> tracer,
                          MakeEmbreeTracer(mesh.mesh, tracer_options));
  return render::CastPanel(mesh, *tracer, camera, Shading(o, frame));
}

// The limit surface of `base`, displaced by `map` (as `use` says) or not, tessellated at the
// map's densities when `density_map` is given, else at o.density.
StatusOr<render::ShadedMesh> Surface(const Mesh& base, const LimitSurface& surface,
                                     const PtexFile* density_map, const PtexFile* map,
                                     const MapUse& use, const SurfaceRenderOptions& o) {
  const auto density = Densities(surface, density_map, o);
  return render::TessellateLimitSurface(base, surface, density, map, use.channel,
                                        o.per_face_displacement
                                            ? render::BoundaryDisplacement::kPerFace
                                            : render::BoundaryDisplacement::kMean,
                                        use.space);
}

}  // namespace

StatusOr<Image> RenderSurface(const Mesh& base, const PtexFile* map,
                              const SurfaceRenderOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateSurfaceRenderOptions(options));
  return RunWithThreads(options.threads, [&]() -> StatusOr<Image> {
    DISPEX_ASSIGN_OR_RETURN(LimitSurface surface, LimitSurface::Build(base));
    MapUse use;
    if (map) {
      DISPEX_ASSIGN_OR_RETURN(use, CheckMap(base, surface, *map, options.channel));
    }
    DISPEX_ASSIGN_OR_RETURN(render::ShadedMesh mesh,
                            Surface(base, surface, map, map, use, options));
    return Cast(mesh, base.positions, options, options.width, options.height);
  });
}

StatusOr<Image> RenderMesh(const Mesh& mesh, std::span<const Float3> frame,
                           const SurfaceRenderOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateSurfaceRenderOptions(options));
  return RunWithThreads(options.threads, [&]() -> StatusOr<Image> {
    const render::ShadedMesh shaded = render::ShadePolygonMesh(mesh);
    return Cast(shaded, frame, options, options.width, options.height);
  });
}

StatusOr<Image> RenderComparison(const Mesh& base, const PtexFile& map, const Mesh* sculpt,
                                 const SurfaceRenderOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateSurfaceRenderOptions(options));
  const int panels = sculpt ? 3 : 2;
  const int panel_width = options.width / panels;
  if (panel_width < 16) {
    return Status::Error(
        fmt::format("width x height = {}x{}: {} panels need at least {} pixels of width",
                    options.width, options.height, panels, 16 * panels));
  }
  // Label size: 2x the font from 240 rows, growing with the image (4x at 720 rows).
  const int scale = options.height >= 240 ? std::clamp(options.height / 180, 2, 4) : 1;
  const int strip = render::TextHeight(render::FontSize::kSmall, scale) + 6 * scale;
  const int panel_height = options.height - strip;
  if (panel_height < 16) {
    return Status::Error(
        fmt::format("width x height = {}x{}: too low for labelled panels (at least {})",
                    options.width, options.height, strip + 16));
  }
  return RunWithThreads(options.threads, [&]() -> StatusOr<Image> {
    DISPEX_ASSIGN_OR_RETURN(LimitSurface surface, LimitSurface::Build(base));
    DISPEX_ASSIGN_OR_RETURN(const MapUse use, CheckMap(base, surface, map, options.channel));
    const std::span<const Float3> frame = base.positions;
    Image image(options.width, options.height, render::kPanelBackground);
    const char* labels[3] = {"base", "base + map", "sculpt"};
    for (int k = 0; k < panels; ++k) {
      std::optional<Image> panel;
      if (k < 2) {
        DISPEX_ASSIGN_OR_RETURN(
            render::ShadedMesh mesh,
            Surface(base, surface, &map, k == 1 ? &map : nullptr, use, options));
        DISPEX_ASSIGN_OR_RETURN(panel, Cast(mesh, frame, options, panel_width, panel_height));
      } else {
        const render::ShadedMesh mesh = render::ShadePolygonMesh(*sculpt);
        DISPEX_ASSIGN_OR_RETURN(panel, Cast(mesh, frame, options, panel_width, panel_height));
      }
      const int x = k * panel_width;
      render::Blit(image, *panel, x, strip);
      const int text_width = render::TextWidth(labels[k], render::FontSize::kSmall, scale);
      render::DrawText(image, x + (panel_width - text_width) / 2, 3 * scale, labels[k],
                       render::FontSize::kSmall, scale, kLabel);
    }
    return image;
  });
}

}  // namespace dispex
