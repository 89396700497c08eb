// Proving maps: sculpts whose true displacement is known (MakeSculpt), and measuring any map
// against any sculpt (Verify).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/ids.h"
#include "dispex/status.h"

namespace dispex {

// ---- Ground-truth sculpts ------------------------------------------------------------------

// Known displacement patterns h. All but kImage are functions of the limit point P in object
// space, scaled by the base's bounding box (diagonal D) and the sculpt's edge length e (the
// base's median edge length / 2^levels) so that every pattern is resolved by the sculpt it is
// put on.
enum class Pattern : std::uint8_t {
  kSmooth,  // three long sines (wavelengths 0.6, 0.35, 0.25 D)
  kDetail,  // smooth + bumps of wavelength 8e confined to two balls of radius 0.22 D + a few
            // sharp ridges (tents 0.02 D wide on planes 0.25 D apart)
  kRidges,  // smooth + a triangle wave of period 0.12 D: sharp creases (C0) along planes
  kNoise,   // 24 sines of random directions and wavelengths in [6e, 24e] (seeded)
  kNone,    // h = 0: the refined limit surface itself (e.g. a denser base cage)
  // A height image (PNG) through the cage's UVs: h = A (2 L - 1), L in [0, 1] the image's
  // luminance at the point's UV. The point's UV is the cage's face-varying UVs interpolated
  // linearly at its (Ptex face, u, v): bilinear over a quad's four corner UVs; on sub-face k
  // of an n-gon bilinear over (corner k, midpoint of edge k, the face's centroid, midpoint of
  // edge k-1), at Ptex (0,0), (1,0), (1,1), (0,1) -- OpenSubdiv's linear face-varying
  // interpolation, exact in closed form. The image: 8- or 16-bit grey, grey + alpha, RGB or
  // RGBA (palettes expanded, alpha ignored); L = 0.2126 R + 0.7152 G + 0.0722 B (Rec. 709
  // weights) on the stored values over 255 or 65535, no gamma decoding (grey: L = value /
  // max). Read with bilinear filtering between pixel centres, repeating outside [0, 1)
  // (pixel (i, j) centred at ((i + 0.5) / width, (j + 0.5) / height)), v = 0 at the image's
  // BOTTOM row (the OBJ / Maya convention). At a UV seam h is continuous only where the image
  // agrees on both sides; a sculpt vertex on a seam takes h from the Ptex face its truth
  // record names.
  kImage,
};
// "smooth", "detail", "ridges", "noise", "none", "image".
std::string_view PatternName(Pattern pattern);
// One of the names above except "image" (which needs a file: ParsePatternArgument).
StatusOr<Pattern> ParsePattern(std::string_view name);

// The --pattern argument of make-sculpt: a pattern name, or "image:FILE.png".
struct PatternArgument {
  Pattern pattern = Pattern::kDetail;
  std::string image_path;  // kImage only
};
StatusOr<PatternArgument> ParsePatternArgument(std::string_view text);

struct PatternFrame {
  float center[3] = {0, 0, 0};  // the base's bounding-box centre
  double diagonal = 1;          // the base's bounding-box diagonal D
  double edge = 0.01;           // the sculpt's edge length e
  double amplitude = 0.01;      // A, object units
  std::uint32_t seed = 1;
};

// h at one point, for the patterns that are functions of the position (NaN for kImage, which
// MakeSculpt evaluates through the cage's UVs).
double EvaluatePattern(Pattern pattern, const PatternFrame& frame, const float p[3]);

struct MakeSculptOptions {
  std::string cage_path;
  std::string output_path;  // the sculpt, OBJ
  std::string truth_path;   // empty: output_path + ".truth"
  int levels = 4;           // uniform Catmull-Clark refinements, 1..8
  Pattern pattern = Pattern::kDetail;
  std::string image_path;   // Pattern::kImage: the height image (PNG)
  double amplitude = 0;     // object units; 0: 1% of the base's bounding-box diagonal
  std::uint32_t seed = 1;
  int threads = 0;
};

struct MakeSculptReport {
  std::size_t vertices = 0, faces = 0;
  double amplitude = 0, diagonal = 0, edge = 0;
  double h_min = 0, h_max = 0;
  // The sculpt's own piecewise-linear error: over every sculpt quad, the largest distance from
  // the true displaced surface at the quad's parametric centre to the midpoints of the quad's
  // two diagonals (where a ray tracer's triangles put the centre). A map extracted from the
  // sculpt cannot be closer to the truth than this.
  double linear_error = 0;
  // Sculpt quads turned inside out: the displaced surface folds there (|h| x curvature >= 1),
  // so rays along the limit normal can miss it or meet another sheet.
  std::size_t folded_faces = 0;
  std::vector<std::string> warnings;  // one line each (tags of the cage that were ignored)
  double seconds = 0;
};

// Refines the cage `levels` times (OpenSubdiv, tags honoured), puts each vertex on the limit
// surface and moves it along the limit normal by h. Writes the sculpt (OBJ, quads) and the
// truth file: for every sculpt vertex its (Ptex face, u, v) on the base and h there. With
// Pattern::kImage, fails before refining (one line naming the file) when the cage has no UVs
// on every face or the image cannot be read (missing, not a PNG, truncated, corrupt, larger
// than 2^28 pixels).
StatusOr<MakeSculptReport> MakeSculpt(const MakeSculptOptions& options);

// The truth file: "DISPEXGT" magic, u32 version (1), u32 zero, u64 count, then count records
// of {i32 Ptex face, f32 u, f32 v, f32 h}, little-endian.
struct GroundTruth {
  std::vector<PtexFaceId> faces;
  std::vector<float> uvs;  // 2 per record
  std::vector<float> h;
  std::size_t size() const { return h.size(); }
};
Status WriteGroundTruth(const std::string& path, const GroundTruth& truth);
StatusOr<GroundTruth> ReadGroundTruth(const std::string& path);

}  // namespace dispex

namespace dispex {

// ---- Measuring a map -----------------------------------------------------------------------

struct VerifyOptions {
  std::string base_path;
  std::string sculpt_path;  // may be empty with truth_path: then only the truth is compared
  std::string map_path;
  std::string truth_path;   // a make-sculpt truth file: compare the map with the exact h
  // Samples per side of each Ptex face for the displaced surface: 0 = twice the face's map
  // resolution, between 8 and 64.
  int samples_per_face = 0;
  // Sculpt vertices measured against the displaced surface: at most this many, evenly
  // strided (0: all).
  std::size_t max_sculpt_points = 2'000'000;
  double max_error = 0;      // fail when an error's max exceeds this (object units; 0: off)
  double max_error_rel = 0;  // the same relative to the base bounding-box diagonal
  double max_rms = 0;        // fail when an RMS error exceeds this (object units; 0: off)
  int threads = 0;
};

struct ErrorStats {
  std::size_t count = 0;
  double mean = 0, rms = 0, p99 = 0, max = 0;  // of absolute values
};

struct VerifyReport {
  double diagonal = 0;
  std::size_t ptex_faces = 0;
  int samples_per_face_min = 0, samples_per_face_max = 0;
  bool measured_distances = false;
  ErrorStats map_to_sculpt;  // displaced limit surface -> nearest sculpt point
  ErrorStats sculpt_to_map;  // sculpt vertices -> nearest point of the displaced surface
  bool measured_truth = false;
  ErrorStats truth;          // |map(face, u, v) - h| at every truth record
  double truth_signed_mean = 0;
  struct WorstFace {
    int face = -1;
    double max = 0;
  };
  std::vector<WorstFace> worst_faces;  // by map -> sculpt max, at most 10
  // From the map's own meta data, when dispex wrote it.
  std::int64_t map_misses = -1, map_holes_filled = -1, map_faces_filled_from_neighbours = -1;
  double map_tolerance = 0;
  bool passed = true;
  std::string failure;                // why it did not pass
  std::vector<std::string> warnings;  // one line each (tags of the base that were ignored)
  double seconds = 0;
};

// Re-displaces the base limit surface with the map (read bilinearly, as a renderer would) and
// measures it against the sculpt both ways, and/or against a truth file.
StatusOr<VerifyReport> Verify(const VerifyOptions& options);

std::string VerifyReportJson(const VerifyReport& report);
std::string VerifyReportSummary(const VerifyReport& report);

}  // namespace dispex
