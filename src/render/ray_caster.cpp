// Panel ray casting: one batch of camera rays per image row through Tracer::Intersect, then
// per hit Phong-interpolated normals (barycentrics by Moller-Trumbore, "Fast, minimum storage
// ray/triangle intersection", 1997) and a fixed light rig in camera space: a headlight, a key
// light from the upper left and a fill from the right (the usual three-point rig without the
// rim light), Lambert diffuse plus a Blinn highlight from the key. Optional ambient occlusion
// casts cosine-distributed rays (Malley's method) whose directions come from a hash of the
// pixel, the sample and a seed: deterministic, and independent of the thread count.
#include "render/ray_caster.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/vec3.h"

namespace dispex::render {

namespace {

// A 32-bit integer mix (xorshift-multiply rounds), for per-pixel sample sequences.
std::uint32_t Mix(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
double Uniform(std::uint32_t bits) {
  return (bits >> 8) * (1.0 / 16777216.0);
}

double ToLinear(std::uint8_t c) {
  return std::pow(c / 255.0, 2.2);
}
std::uint8_t ToDisplay(double linear) {
  return static_cast<std::uint8_t>(
      std::lround(255.0 * std::pow(std::clamp(linear, 0.0, 1.0), 1.0 / 2.2)));
}

constexpr Vec3d kClay = {0.62, 0.56, 0.48};      // front faces, linear
constexpr Vec3d kBackClay = {0.30, 0.38, 0.55};  // back faces (inside of open surfaces)

struct Rig {
  Vec3d key, fill;
};

struct RowScratch {
  std::vector<Ray> rays, ao_rays;
  std::vector<RayHit> hits, ao_hits;
  std::vector<Vec3d> normal, geometric, colour;  // per camera ray
  std::vector<double> ao;
  std::vector<int> ao_owner;
};

// What every row of a panel shares: the scene, the camera, the light rig fixed to it.
struct Panel {
  Panel(const ShadedMesh& shaded, const Tracer& scene, const Camera& view,
        const ShadingOptions& shading)
      : mesh(shaded),
        tracer(scene),
        camera(view),
        options(shading),
        width(view.width),
        ss(shading.supersample),
        per_pixel(ss * ss) {
    const Vec3d right = ToVec3d(camera.right), up = ToVec3d(camera.up),
                back = ToVec3d(camera.forward) * -1.0;
    rig = {Normalize(right * -0.7 + up * 0.6 + back * 0.4),
           Normalize(right * 0.7 + up * 0.05 + back * 0.7)};
  }

  const ShadedMesh& mesh;
  const Tracer& tracer;
  const Camera& camera;
  const ShadingOptions& options;
  int width, ss, per_pixel;  // ss x ss rays per pixel
  Rig rig;
  Vec3d background = {ToLinear(kPanelBackground[0]), ToLinear(kPanelBackground[1]),
                      ToLinear(kPanelBackground[2])};  // linear
};

// Row y's camera rays, ss x ss per pixel on a fixed grid, pixel by pixel.
void CameraRays(const Panel& panel, int y, RowScratch& s) {
  const int ss = panel.ss, per_pixel = panel.per_pixel;
  for (int x = 0; x < panel.width; ++x) {
    for (int k = 0; k < per_pixel; ++k) {
      Ray& ray = s.rays[static_cast<std::size_t>(x) * per_pixel + k];
      panel.camera.RayThrough(x + (k % ss + 0.5) / ss, y + (k / ss + 0.5) / ss, ray.origin,
                              ray.direction);
      ray.tnear = 0;
      ray.tfar = std::numeric_limits<float>::infinity();
    }
  }
}

// Per hit: the vertex normals interpolated at the hit (Phong), the geometric normal, both
// turned towards the viewer, and the clay colour of the side seen.
void HitNormals(const ShadedMesh& mesh, std::size_t count, RowScratch& s) {
  const auto& P = mesh.mesh.positions;
  const auto& I = mesh.mesh.face_indices;
  for (std::size_t r = 0; r < count; ++r) {
    const RayHit& hit = s.hits[r];
    if (!hit.hit()) continue;
    const auto t = static_cast<std::size_t>(hit.prim.value);
    const std::size_t i0 = static_cast<std::size_t>(I[3 * t]);
    const std::size_t i1 = static_cast<std::size_t>(I[3 * t + 1]);
    const std::size_t i2 = static_cast<std::size_t>(I[3 * t + 2]);
    const Vec3d a = ToVec3d(P[i0]), b = ToVec3d(P[i1]), c = ToVec3d(P[i2]);
    const Vec3d d = ToVec3d(s.rays[r].direction), o = ToVec3d(s.rays[r].origin);
    const Vec3d e1 = b - a, e2 = c - a, p = Cross(d, e2);
    const double det = Dot(e1, p);
    double bu = 1.0 / 3, bv = 1.0 / 3;
    if (std::fabs(det) > 0) {
      const Vec3d tv = o - a, q = Cross(tv, e1);
      bu = Dot(tv, p) / det;
      bv = Dot(d, q) / det;
      bu = std::clamp(bu, 0.0, 1.0);
      bv = std::clamp(bv, 0.0, 1.0 - bu);
    }
    Vec3d n = Normalize(ToVec3d(mesh.normals[i0]) * (1.0 - bu - bv) +
                        ToVec3d(mesh.normals[i1]) * bu + ToVec3d(mesh.normals[i2]) * bv);
    Vec3d g = ToVec3d(hit.normal);
    if (Dot(g, d) > 0) {  // the back side: shade the side we see
      g = g * -1.0;
      n = n * -1.0;
      s.colour[r] = kBackClay;
    } else {
      s.colour[r] = kClay;
    }
    // A shading normal turned away from the viewer (grazing, at silhouettes) is bent back.
    const double facing = Dot(n, d);
    if (facing > 0) n = Normalize(n - d * (facing + 1e-3));
    s.normal[r] = n;
    s.geometric[r] = g;
  }
}

// The AO rays of hit r of row y: cosine-distributed about its geometric normal, from a hash
// of the pixel, the sample and the seed.
void AppendOcclusionRays(const ShadingOptions& options, int y, std::size_t r, RowScratch& s) {
  const Vec3d g = s.geometric[r];
  const Vec3d t1 = Normalize(std::fabs(g.x) > 0.5 ? Cross(g, {0, 1, 0}) : Cross(g, {1, 0, 0}));
  const Vec3d t2 = Cross(g, t1);
  const Vec3d hit_point = ToVec3d(s.rays[r].origin) + ToVec3d(s.rays[r].direction) * s.hits[r].t;
  const Vec3d origin = hit_point + g * (1e-3 * options.ao_distance);
  const std::uint32_t pixel =
      Mix(static_cast<std::uint32_t>(y) * 0x9e3779b9u ^ static_cast<std::uint32_t>(r)) ^
      options.seed;
  for (int k = 0; k < options.ao_samples; ++k) {
    const std::uint32_t bits = Mix(pixel + static_cast<std::uint32_t>(k) * 0x632be5abu);
    const double u1 = Uniform(bits), u2 = Uniform(Mix(bits ^ 0x5bd1e995u));
    const double radius = std::sqrt(u2), phi = 2.0 * std::numbers::pi * u1;
    const Vec3d dir = t1 * (radius * std::cos(phi)) + t2 * (radius * std::sin(phi)) +
                      g * std::sqrt(std::max(0.0, 1.0 - u2));
    Ray ray;
    ray.origin = FromVec3d<Float3>(origin);
    ray.direction = FromVec3d<Float3>(Normalize(dir));
    ray.tnear = 0;
    ray.tfar = options.ao_distance;
    s.ao_rays.push_back(ray);
    s.ao_owner.push_back(static_cast<int>(r));
  }
}

// s.ao: per camera ray of row y, the fraction of its AO rays that escape (1 without AO).
void AmbientOcclusion(const Panel& panel, int y, std::size_t count, TraceCounters& counters,
                      RowScratch& s) {
  const ShadingOptions& options = panel.options;
  s.ao.assign(count, 1.0);
  if (options.ao_samples <= 0) return;
  s.ao_rays.clear();
  s.ao_owner.clear();
  for (std::size_t r = 0; r < count; ++r) {
    if (s.hits[r].hit()) AppendOcclusionRays(options, y, r, s);
  }
  s.ao_hits.resize(s.ao_rays.size());
  panel.tracer.Intersect(s.ao_rays, s.ao_hits, counters);
  for (std::size_t k = 0; k < s.ao_rays.size(); ++k) {
    if (s.ao_hits[k].hit())
      s.ao[static_cast<std::size_t>(s.ao_owner[k])] -= 1.0 / options.ao_samples;
  }
}

// Adds camera ray r's colour (linear) to `sum`: the clay lit by the rig, darkened by
// occlusion, plus the key's highlight.
void AddShade(const Panel& panel, const RowScratch& s, std::size_t r, Vec3d& sum) {
  const Rig& rig = panel.rig;
  const Vec3d n = s.normal[r], view = ToVec3d(s.rays[r].direction) * -1.0;
  const double occlusion = 0.35 + 0.65 * std::max(0.0, s.ao[r]);
  const double diffuse = 0.08 + 0.25 * std::max(0.0, Dot(n, view)) +
                         0.75 * std::max(0.0, Dot(n, rig.key)) +
                         0.20 * std::max(0.0, Dot(n, rig.fill));
  const double specular =
      Dot(n, rig.key) > 0 ? 0.10 * std::pow(std::max(0.0, Dot(n, Normalize(rig.key + view))), 48)
                          : 0.0;
  sum = sum + s.colour[r] * (diffuse * occlusion) + Vec3d{specular, specular, specular};
}

// Row y's pixels: the mean of their rays' colours, the background where a ray misses; pixels
// whose rays all miss are left as the background.
void ShadeRow(const Panel& panel, int y, const RowScratch& s, Image& image) {
  const int per_pixel = panel.per_pixel;
  for (int x = 0; x < panel.width; ++x) {
    Vec3d sum;
    int hits = 0;
    for (int k = 0; k < per_pixel; ++k) {
      const std::size_t r = static_cast<std::size_t>(x) * per_pixel + k;
      if (!s.hits[r].hit()) {
        sum = sum + panel.background;
        continue;
      }
      ++hits;
      AddShade(panel, s, r, sum);
    }
    if (hits == 0) continue;  // exactly the background
    const Vec3d mean = sum * (1.0 / per_pixel);
    image.set(x, y, {ToDisplay(mean.x), ToDisplay(mean.y), ToDisplay(mean.z)});
  }
}

}  // namespace

StatusOr<Image> CastPanel(const ShadedMesh& mesh, const Tracer& tracer, const Camera& camera,
                          const ShadingOptions& options) {
  const int w = camera.width, h = camera.height;
  Image image(w, h, kPanelBackground);
  const Panel panel(mesh, tracer, camera, options);

  tbb::enumerable_thread_specific<RowScratch> scratches;
  tbb::parallel_for(0, h, [&](int y) {
    RowScratch& s = scratches.local();
    const std::size_t count = static_cast<std::size_t>(w) * panel.per_pixel;
    s.rays.resize(count);
    s.hits.resize(count);
    s.normal.resize(count);
    s.geometric.resize(count);
    s.colour.resize(count);
    CameraRays(panel, y, s);
    TraceCounters counters;
    tracer.Intersect(s.rays, s.hits, counters);
    HitNormals(mesh, count, s);
    AmbientOcclusion(panel, y, count, counters, s);
    ShadeRow(panel, y, s, image);
  });
  DISPEX_RETURN_IF_ERROR(tracer.status());
  return image;
}

}  // namespace dispex::render
