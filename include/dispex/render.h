// Pictures of a displacement map, for people: the map itself as a grid atlas of its Ptex faces
// (RenderAtlas), and the base mesh's limit surface ray-cast without and with the map, beside
// the sculpt (RenderSurface, RenderComparison). Images are 8-bit RGB, written as PNG.
//
// Everything here is deterministic: the same inputs and options give the same pixels whatever
// the thread count (work is split over rows and faces; no randomness but fixed per-pixel
// sequences).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/status.h"

namespace dispex {

// ---- Images --------------------------------------------------------------------------------

// 8-bit RGB, rows top to bottom, pixel (x, y) at rgb[3 * (y * width + x)].
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  Image() = default;
  // A width x height image filled with `fill`. Preconditions: width, height >= 0.
  Image(int w, int h, std::array<std::uint8_t, 3> fill = {0, 0, 0});

  // Preconditions: 0 <= x < width, 0 <= y < height.
  std::array<std::uint8_t, 3> at(int x, int y) const;
  void set(int x, int y, std::array<std::uint8_t, 3> colour);
};

// Encodes `image` as an 8-bit RGB PNG (libpng) in memory. Fails for an empty image, a size
// over 2^31 - 1 bytes of pixels, or a pixel array of the wrong size.
StatusOr<std::vector<std::uint8_t>> EncodePng(const Image& image);

// Writes `image` as a PNG to `path` atomically (a temporary file renamed over the target):
// the file appears whole or not at all. Fails as EncodePng does, or naming the path when the
// directory is missing or not writable.
Status WritePng(const std::string& path, const Image& image);

// Reads a PNG of any colour type and bit depth as 8-bit RGB (grey expanded, palette expanded,
// 16-bit channels reduced, alpha dropped). Fails, naming the file, when it is missing, not a
// PNG, truncated or corrupt, or larger than 2^28 pixels.
StatusOr<Image> ReadPng(const std::string& path);
// The same from bytes in memory; `name` is used in messages.
StatusOr<Image> DecodePng(const std::uint8_t* data, std::size_t size, const std::string& name);

// Parses "WxH" (e.g. "960x360"): both integers in 1..16384. The message names the text.
StatusOr<std::array<int, 2>> ParseImageSize(std::string_view text);

// ---- The atlas of a map --------------------------------------------------------------------

enum class AtlasMode : std::uint8_t {
  kGrey,    // black = low end of the range, white = high end
  kSigned,  // green positive, red negative, black zero; intensity proportional to |value|
  // Three channels from `channel` on as red, green, blue (a vector map's x, y, z or T, B, N):
  // each component as kGrey draws it over the range, so 128 grey is the zero vector.
  kVector,
};
std::string_view AtlasModeName(AtlasMode mode);  // "grey", "signed", "vector"
// The mode a map is best shown in: kVector for a vector map (one with dispex:vector_space and
// three channels or more), kSigned otherwise.
AtlasMode DefaultAtlasMode(const PtexFile& map);
StatusOr<AtlasMode> ParseAtlasMode(std::string_view name);

struct AtlasOptions {
  AtlasMode mode = AtlasMode::kSigned;
  // 0: automatic. kSigned and kVector: [-m, m], m the largest |value| shown (of any of the
  // three components); kGrey: [min, max] of the values shown. A positive number A: [-A, A].
  double range = 0;
  int channel = 0;  // the channel drawn; kVector: the first of three
  // Each tile is its face's ures x vres texels, each side scaled by the smallest integer factor
  // that makes it at least min_tile pixels (2..256), as far as max_tile allows. Faces whose
  // larger side exceeds max_tile pixels (16..4096) are shown reduced by a power of two (the
  // mean of each block of texels).
  int min_tile = 16;
  int max_tile = 256;
  // Width of the tile area in pixels; 0: automatic (about square, at least 320). Widened to
  // the widest tile when narrower.
  int width = 0;
  // Draw each face's id in the top-left corner of its tile (3x5 digits); tiles are then made
  // large enough to hold their label.
  bool labels = false;
  int threads = 0;  // 0: all cores
};

// Checks the ranges of the options that do not depend on a map; the message names the field
// and its value ("max_tile = 8: must be 16..4096").
Status ValidateAtlasOptions(const AtlasOptions& options);

struct AtlasRect {
  int x = 0, y = 0, width = 0, height = 0;  // pixels; (x, y) is the top-left corner
};

// Where RenderAtlas put things. Tile f shows face f: pixel (x, y) of the tile (from its
// top-left corner) shows texel (x / scale_x, vres' - 1 - y / scale_y) of the face at its shown
// resolution ures' x vres' (v = 0 is the bottom row, as in the face's (u, v) parameter space).
struct AtlasLayout {
  struct Tile {
    AtlasRect rect;
    int scale_x = 1, scale_y = 1;  // pixels per shown texel along u and along v
    int reduction = 0;             // shown at level-0 resolution divided by 2^reduction
  };
  std::vector<Tile> tiles;  // one per Ptex face, in face-id order
  AtlasRect legend;         // the whole legend strip (below the tiles)
  AtlasRect legend_bar;     // the colour gradient: left end = range_min, right end = range_max
  double range_min = 0, range_max = 0;  // the value range the colours span
  int width = 0, height = 0;            // of the image
};

// Tiles laid out in face-id order, left to right in rows (a row is as tall as its tallest
// tile), one-pixel separators, a legend strip below: the gradient bar with the minimum,
// middle and maximum values written under it. Non-finite texels are drawn magenta and are
// left out of the automatic range. Fails for a triangle-mesh Ptex file, a channel out of
// range (kVector: channel + 2 past the last), options out of range, a face whose data is corrupt
// (naming the face), or an image over 2^27 pixels. `layout`, when given, receives the positions.
StatusOr<Image> RenderAtlas(const PtexFile& map, const AtlasOptions& options,
                            AtlasLayout* layout = nullptr);

// The colour of `value` for a range (lo, hi) in a mode, exactly as the atlas draws it:
//   kGrey:   g = round(255 * clamp((value - lo) / (hi - lo), 0, 1)), (g, g, g); hi == lo gives
//            128 grey;
//   kSigned: m = max(|lo|, |hi|), c = round(255 * min(1, |value| / m)): (0, c, 0) for value > 0,
//            (c, 0, 0) for value < 0, black for 0 (and for m == 0);
//   kVector: one component, as kGrey (AtlasVectorColour combines three);
// magenta (255, 0, 255) for a value that is not finite.
std::array<std::uint8_t, 3> AtlasColour(AtlasMode mode, double lo, double hi, float value);
// kVector's pixel: the red, green and blue of AtlasColour(kGrey, lo, hi, .) of the three
// components; magenta when any of them is not finite.
std::array<std::uint8_t, 3> AtlasVectorColour(double lo, double hi, const float* components);

// ---- Rendering the surface -----------------------------------------------------------------

// Views around the object, +y up: front looks from +z, back from -z, right from +x, left from
// -x, top from +y (image up = -z), iso from (+x, +y, +z) (azimuth 45, elevation 35.26).
enum class ViewPreset : std::uint8_t { kFront, kBack, kLeft, kRight, kTop, kIso };
std::string_view ViewName(ViewPreset view);  // "front", "back", "left", "right", "top", "iso"
StatusOr<ViewPreset> ParseView(std::string_view name);

enum class Projection : std::uint8_t { kPerspective, kOrthographic };
std::string_view ProjectionName(Projection projection);  // "perspective", "ortho"
StatusOr<Projection> ParseProjection(std::string_view name);

struct ViewOptions {
  ViewPreset preset = ViewPreset::kIso;
  // Degrees; NaN: the preset's. Azimuth turns about +y from the front (+z) towards +x
  // (90 = right); elevation raises the eye towards +y (90 = straight down), within [-90, 90].
  double azimuth = std::numeric_limits<double>::quiet_NaN();
  double elevation = std::numeric_limits<double>::quiet_NaN();
  Projection projection = Projection::kPerspective;
  double fov_degrees = 30;  // vertical field of view (perspective), 1..120
  // Empty border left around the framed points, as a fraction of the image (0..0.45).
  double margin = 0.06;
};

// A pinhole or orthographic camera with square pixels and a shifted image window (a "shift
// lens", so framing can centre the object without turning the camera). Pixel (x, y) covers
// [x, x+1) x [y, y+1) in continuous image coordinates, y down.
struct Camera {
  Float3 eye;      // perspective: the centre of projection; ortho: a point on the image plane
  Float3 forward;  // unit viewing direction
  Float3 right;    // unit, image +x
  Float3 up;       // unit, image -y
  Projection projection = Projection::kPerspective;
  // Half the image height, and the image centre's offset along right and up, in world units at
  // distance 1 (perspective; half_height = tan(fov / 2)) or on the image plane (ortho).
  double half_height = 1;
  double shift_x = 0, shift_y = 0;
  int width = 1, height = 1;

  // The ray through continuous image point (px, py): origin and unit direction.
  void RayThrough(double px, double py, Float3& origin, Float3& direction) const;
  // The continuous image point a world point projects to; false when it lies behind a
  // perspective camera.
  bool Project(const Float3& point, double& px, double& py) const;
};

// The camera for `view` that frames `points` (e.g. a cage's vertices: the limit surface lies
// in their convex hull) in a width x height image: the view direction comes from the preset
// or angles; the camera looks from the points' bounding-box centre's side at the smallest
// distance (perspective) or zoom (ortho) that keeps every point inside the image less the
// margin, with the window shifted so the points' extent is centred. Fails for no points, a
// point that is not finite, a size below 1, an elevation outside [-90, 90], a non-finite
// azimuth, or a field of view or margin out of range.
StatusOr<Camera> FrameCamera(std::span<const Float3> points, const ViewOptions& view, int width,
                             int height);
// The same for the eight corners of `box`.
StatusOr<Camera> FrameCamera(const BoundingBox& box, const ViewOptions& view, int width,
                             int height);

struct SurfaceRenderOptions {
  int width = 800, height = 600;  // of the whole image (all panels together)
  ViewOptions view;
  // Tessellation: without a map every Ptex face gets density x density quads; with a map a
  // face of ures x vres texels gets clamp(ures, min_density, max_density) x clamp(vres, ...)
  // quads. Neighbouring faces of different density are stitched (no cracks, no T-junctions).
  int density = 16;           // 1..256
  int min_density = 8;        // 1..256
  int max_density = 64;       // min_density..256
  int supersample = 2;        // s x s rays per pixel on a fixed grid (1..4)
  int ao_samples = 0;         // ambient occlusion rays per hit (0 = off, up to 64)
  double ao_distance = 0.05;  // AO ray length, fraction of the framed points' bounding diagonal
  // -1: the map says what it holds: 1 channel, a scalar map (P + h N); 3 channels with
  // dispex:vector_space meta data, a vector map (P + D, include/dispex/vector_space.h); any
  // other map is an error naming it. 0 or more: that channel as a scalar map, whatever the map.
  int channel = -1;
  int threads = 0;  // 0: all cores
  // Where faces meet, displace each face by its own map value instead of the faces' mean, as
  // a renderer that reads each face on its own (PtexFile::Sample, no filtering across edges)
  // does: every face gets its own copy of the shared points (same undisplaced limit position
  // and normal), so where the faces' values differ the displaced surface cracks or steps and
  // the shading shows a seam there, and the picture shows what such a renderer shows. The
  // default (false) averages the values, so no cracks open. Without a map it changes nothing.
  bool per_face_displacement = false;
};

// Checks every option's range, the view's included (width, height, density, min_density,
// max_density, supersample, ao_samples, ao_distance, channel, threads, azimuth, elevation,
// fov_degrees, margin); the message names the field and its value.
Status ValidateSurfaceRenderOptions(const SurfaceRenderOptions& options);

// Renders the limit surface of the Catmull-Clark cage `base`, displaced along its limit normal
// by `map` (read bilinearly per face, as a renderer reads it; values averaged where faces
// meet, so no cracks open, unless options.per_face_displacement) when map is not null -- by
// the vector D of a vector map (options.channel) --, framed
// on the cage's vertices. Shading: clay albedo lit by a headlight and a two-light rig (key and
// fill), smooth normals averaged from the displaced tessellation; hidden holes show the
// background. Fails when the cage is not a valid Catmull-Clark mesh, the map's face count
// differs from the cage's Ptex face count (naming both), the map is a triangle Ptex or lacks
// the channel, is neither a scalar nor a vector map (options.channel = -1), its data is
// corrupt or not finite, or options are out of range.
StatusOr<Image> RenderSurface(const Mesh& base, const PtexFile* map,
                              const SurfaceRenderOptions& options);

// Renders any polygon mesh (e.g. the sculpt) with the same shading, framed on the points
// `frame` (pass the base cage's positions to match RenderSurface's framing). Normals are
// averaged from the mesh's own faces.
StatusOr<Image> RenderMesh(const Mesh& mesh, std::span<const Float3> frame,
                           const SurfaceRenderOptions& options);

// One options.width x options.height image of side-by-side panels, each options.width / panels
// wide (leftover columns on the right stay background), under a label strip: "base" (the limit
// surface tessellated as for the map, not displaced), "base + map", and "sculpt" when `sculpt`
// is not null, all with the same camera framed on the base cage's vertices. Fails as
// RenderSurface does, or when a panel would be under 16 pixels wide or high.
StatusOr<Image> RenderComparison(const Mesh& base, const PtexFile& map, const Mesh* sculpt,
                                 const SurfaceRenderOptions& options);

// The preview images of a map: writes DIR/<stem>_atlas.png (signed atlas, automatic
// range) and DIR/<stem>_compare.png (base | base + map, 960 x 360, iso view), <stem> being
// the map's file name without its extension. Creates DIR when missing. Fails naming the file
// that could not be read or written.
Status WritePreviews(const std::string& base_path, const std::string& map_path,
                     const std::string& dir);

}  // namespace dispex
