// Proving maps: sculpts whose true displacement is known (MakeSculpt), and measuring any map
// against any sculpt (Verify).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/ids.h"
#include "dispex/status.h"
#include "dispex/vector_space.h"

namespace dispex {

// ---- Ground-truth sculpts ------------------------------------------------------------------

// Known displacement patterns. The scalar ones give a height h, and the displacement D = h N
// along the limit normal N; the vector ones (kSideways, kOverhang) give D with tangential
// parts. All but kImage are functions of the limit point P in object space (and N), scaled by
// the base's bounding box (diagonal D, centre c; p = P - c below) and the sculpt's edge length
// e (the base's median edge length / 2^levels, or / density) so that every pattern is resolved
// by the sculpt it is put on.
enum class Pattern : std::uint8_t {
  kSmooth,  // three long sines (wavelengths 0.6, 0.35, 0.25 D)
  kDetail,  // smooth + bumps of wavelength 8e confined to two balls of radius 0.22 D + a few
            // sharp ridges (tents 0.02 D wide on planes 0.25 D apart)
  kRidges,  // smooth + a triangle wave of period 0.12 D: sharp creases (C0) along planes
  kNoise,   // 24 sines of random directions and wavelengths in [6e, 24e] (seeded)
  kNone,    // h = 0: the refined limit surface itself (e.g. a denser base cage)
  // The vector patterns move points along t(a) = a - (a.N) N, the projection of a fixed unit
  // axis a onto the tangent plane (of length sin(angle(a, N)): zero, and smooth, where N is
  // parallel to a).
  // Tangential waves only (D.N = 0: no scalar map along N holds any of it): with
  // a1 = (0.6, 0.64, 0.48), a2 = (-0.48, 0.6, 0.64), w2 = (0.64, -0.48, 0.6),
  //   D = A [0.6 sin(2 pi a1.p / (0.3 D) + 0.5) t(a1) + 0.4 sin(2 pi w2.p / (0.15 D) + 1.7) t(a2)]
  // (a wave that stretches and compresses the surface along a1 and one that shears it along
  // a2). Its slope stays below 1 (no triangle of the sculpt turns over) while A < 0.034 D.
  kSideways,
  // Waves that break: bumps h N sheared along the direction they run in,
  //   D = A sin(theta) N + (2 / k) sin(theta) t(a),  theta = k a.p + 0.7,
  // a = (0.8, 0.48, 0.36), k = 2 pi / lambda, lambda = max(4 A, 16 e). Where the surface runs
  // along a (N orthogonal to a) the shear's slope reaches 2 (the tangential part changes along
  // t(a) at 2 cos(theta) |t(a)|^2 per unit length; below -1 the surface runs back): the displaced
  // surface folds back over itself along N, and a line along N through the fold meets it three
  // times, so no scalar map along N can hold it. On a plane the displaced surface is the graph
  // of h sheared by a linear map, so it never intersects itself; on a curved base the same
  // holds while lambda is small against the curvature radius. D.N = h = A sin(theta); the
  // tangential part reaches lambda / pi.
  kOverhang,
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
// "smooth", "detail", "ridges", "noise", "none", "sideways", "overhang", "image".
std::string_view PatternName(Pattern pattern);
// kSideways and kOverhang: D has tangential parts.
bool IsVectorPattern(Pattern pattern);
// One of the names above except "image" (which needs a file: ParsePatternArgument).
StatusOr<Pattern> ParsePattern(std::string_view name);

// A pattern given by name: a pattern name, or "image:FILE.png".
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
// MakeSculpt evaluates through the cage's UVs); for the vector patterns h = D.N, their normal
// part (0 for kSideways, A sin(theta) for kOverhang).
double EvaluatePattern(Pattern pattern, const PatternFrame& frame, const float p[3]);
// The object-space displacement D at the limit point p with unit limit normal n: h n for the
// scalar patterns, the vector patterns' own D (NaN for kImage).
void EvaluatePatternVector(Pattern pattern, const PatternFrame& frame, const float p[3],
                           const float n[3], double d[3]);

// How the sculpt's vertices sit on the base.
enum class SculptLayout : std::uint8_t {
  // The cage refined `levels` times: quads whose vertices lie exactly on the power-of-two
  // texel grids of the Ptex faces, and which extract's oversampling recognises by face count.
  kRefined,
  // `density` x `density` cells per quad Ptex face, density / 2 per n-gon sub-face (so both
  // sides of every base edge have `density` cells; density must be even on cages with
  // n-gons), with vertices at jittered (u, v): interior ones by up to 0.3 cell in u and v, those on
  // a Ptex face's
  // edges by up to 0.3 cell along the edge only, corners and base edge midpoints fixed;
  // vertices on shared edges are shared (named by base vertex, base edge and n-gon spoke), so
  // the sculpt is watertight. Each
  // cell is split into two triangles along a random diagonal (the other one where the
  // random one would flip a triangle in (u, v)). Seeded by `seed`, deterministic.
  kJittered,
};
// "refined", "jittered".
std::string_view SculptLayoutName(SculptLayout layout);
StatusOr<SculptLayout> ParseSculptLayout(std::string_view name);

struct MakeSculptOptions {
  std::string cage_path;
  std::string output_path;  // the sculpt, OBJ or PLY by its name (WriteMesh)
  std::string truth_path;   // empty: output_path + ".truth"
  int levels = 4;           // uniform Catmull-Clark refinements, 1..8 (kRefined only)
  SculptLayout layout = SculptLayout::kRefined;
  int density = 0;  // kJittered: cells per quad face side, 2..256 (0 for kRefined)
  Pattern pattern = Pattern::kDetail;
  std::string image_path;  // Pattern::kImage: the height image (PNG)
  double amplitude = 0;    // object units; 0: 1% of the base's bounding-box diagonal
  std::uint32_t seed = 1;  // the noise pattern's and the jittered layout's
  // kRefined on a cage of quads only: the sculpt written (PLY) as it is evaluated, in memory
  // that grows with the cage, not the sculpt (film-scale assets); the same surface with the
  // vertices in another order. No truth file, no linear error, no folded faces counted.
  bool streamed = false;
  int threads = 0;
};

struct MakeSculptReport {
  std::size_t vertices = 0, faces = 0;  // faces: quads (kRefined) or triangles (kJittered)
  double amplitude = 0, diagonal = 0, edge = 0;
  PatternFrame frame;           // what the pattern was evaluated with (EvaluatePatternVector)
  double h_min = 0, h_max = 0;  // of D.N
  // Over the sculpt's vertices: the largest |D| and the largest tangential part |D - (D.N) N|
  // (0 for the scalar patterns, to rounding).
  double max_displacement = 0, max_tangential = 0;
  // The sculpt's own piecewise-linear error: over every sculpt face, the largest distance from
  // the true displaced surface to the face at the parametric midpoints of its edges and at its
  // centre (a quad's against the midpoints of both diagonals, where a ray tracer's triangles
  // put it; a triangle's centroid). A map extracted from the sculpt cannot be closer to the truth
  // than this. The truth file holds it per vertex, over the faces near the vertex (GroundTruth).
  double linear_error = 0;  // NaN: not measured (streamed)
  // Sculpt faces turned inside out against the limit normal: the displaced surface folds there
  // (|h| x curvature >= 1), so rays along the limit normal can miss it or meet another sheet.
  // Expected of kOverhang (the part of each wave that runs back), where they are no fault.
  std::size_t folded_faces = 0;
  std::vector<std::string> warnings;  // one line each (tags of the cage that were ignored)
  double seconds = 0;
};

// Refines the cage `levels` times (OpenSubdiv, tags honoured) or lays out a jittered grid per
// Ptex face (SculptLayout), puts each vertex P on the limit surface and moves it to P + D (D =
// h N for the scalar patterns). Writes the sculpt (OBJ, quads or triangles) and the truth file
// (version 3): for every sculpt vertex its (Ptex face, u, v) on the base, h = D.N there, the
// local linear error and D. With
// Pattern::kImage, fails before refining (one line naming the file) when the cage has no UVs
// on every face or the image cannot be read (missing, not a PNG, truncated, corrupt, larger
// than 2^28 pixels).
StatusOr<MakeSculptReport> MakeSculpt(const MakeSculptOptions& options);

// The truth file: "DISPEXGT" magic, u32 version, u32 zero, u64 count, then count records,
// little-endian: version 1 {i32 Ptex face, f32 u, f32 v, f32 h}; version 2 adds f32 e_v, the
// sculpt's local linear error (MakeSculptReport::linear_error over the faces within two rings
// of the vertex; infinite when one of them folds against the normal, for the scalar patterns);
// version 3 adds f32 dx, dy, dz, the object-space displacement D at the vertex (the sculpt
// vertex is the limit point + D; h = D.N). Written as version 3 when d is filled (local_error
// must be too), else version 2 when local_error is filled, else version 1; all three are read.
struct GroundTruth {
  std::vector<PtexFaceId> faces;
  std::vector<float> uvs;  // 2 per record
  std::vector<float> h;
  std::vector<float> local_error;  // empty (version 1) or one per record
  std::vector<float> d;            // empty (versions 1 and 2) or 3 per record
  std::size_t size() const { return h.size(); }
  int version() const { return !d.empty() ? 3 : !local_error.empty() ? 2 : 1; }
};
Status WriteGroundTruth(const std::string& path, const GroundTruth& truth);
StatusOr<GroundTruth> ReadGroundTruth(const std::string& path);

}  // namespace dispex

namespace dispex {

// ---- Measuring a map -----------------------------------------------------------------------
//
// A map with 1 channel is a scalar map: the displaced surface is P + h N. A map with 3 channels
// and dispex:vector_space meta data is a vector map: P + D, D = VectorFromChannels(space, the
// frame at (u, v), the channels read at (u, v)) (include/dispex/vector_space.h); anything else
// is an error naming the map (DisplacementMapSpace).

struct VerifyOptions {
  // A mesh already displaced -- by a renderer (tests/blender), by another tool -- measured
  // against the sculpt both ways instead of a map: its vertices to the sculpt, the sculpt's
  // vertices to it. base_path and map_path are then unused; the distance bounds below apply.
  std::string displaced_path;
  std::string base_path;
  std::string sculpt_path;  // may be empty with truth_path: then only the truth is compared
  std::string map_path;
  std::string truth_path;  // a make-sculpt truth file: compare the map with the exact h
  // Samples per side of each Ptex face for the displaced surface: 0 = twice the face's map
  // resolution, between 8 and 64.
  int samples_per_face = 0;
  // Sculpt vertices measured against the displaced surface: at most this many, evenly
  // strided (0: all).
  std::size_t max_sculpt_points = 2'000'000;
  double max_error = 0;      // fail when an error's max exceeds this (object units; 0: off)
  double max_error_rel = 0;  // the same relative to the base bounding-box diagonal
  double max_rms = 0;        // fail when an RMS error exceeds this (object units; 0: off)
  double max_p99 = 0;        // fail when a 99th percentile exceeds this (object units; 0: off)
  // Fail when the mean distance from the sculpt's points to the displaced surface exceeds this
  // many of the map's tolerances (or `tolerance`) (0: off). Judged by default, so that a verify
  // with no bound given still says whether map and sculpt belong together: good maps reach
  // 0.5 (a cube refined twice; the bunny scan 0.25), a map against another asset's sculpt
  // 150. The other way, from the displaced surface, also carries the sagging of the sculpt's
  // facets between its vertices (9.4 tolerances on that cube) and is not judged by default.
  double max_mean_tolerances = 2;
  // Bounds against the truth, scaled by the tolerance tau: this one, or 0 for the map's own
  // (its dispex:statistics meta data); with neither they are not checked.
  double tolerance = 0;
  // Per record of a version-2 or -3 truth file: fail when the record's error
  // (VerifyReport::truth_quantity, e.g. |map - h|) > k tau + 2 e_v at any record,
  // k = truth_local_tolerance_factor and e_v the sculpt's linear error near the vertex
  // (GroundTruth). k > 1: extract holds tau at its samples only; between them, where a
  // coarser texel grid is read, good maps reach 1.3 tau (docs/ACCURACY.md). A Ptex map is
  // read there as a renderer reads it: the reference Ptex filter, across face edges.
  bool truth_local_bound = true;
  double truth_local_tolerance_factor = kDefaultTruthLocalToleranceFactor;
  // Fail when the truth RMS exceeds truth_rms_factor x tau, or its 99th percentile exceeds
  // truth_p99_factor x tau (0: off). Good maps stay under 0.36 tau and 1.26 tau on every
  // sculpt of docs/ACCURACY.md.
  double truth_rms_factor = kDefaultTruthRmsFactor;
  double truth_p99_factor = kDefaultTruthP99Factor;
  // Steps where faces meet (docs/ACCURACY.md, "Watertight edges"): fail when the largest
  // step on a shared edge, under either reader, exceeds max_edge_step x tau, or their 99th
  // percentile exceeds max_edge_step_p99 x tau (0: off). tau as for the truth bounds. Edges
  // on infinitely sharp creases of the base, and beside the faces the map lists as
  // discontinuous, are counted, not checked.
  double max_edge_step = 0;
  double max_edge_step_p99 = 0;
  int threads = 0;
  static constexpr double kDefaultTruthLocalToleranceFactor = 1.5;
  static constexpr double kDefaultTruthRmsFactor = 0.5;
  static constexpr double kDefaultTruthP99Factor = 1.5;
};

struct ErrorStats {
  std::size_t count = 0;
  double mean = 0, rms = 0, p99 = 0, max = 0;  // of absolute values
};

struct VerifyReport {
  // VerifyOptions::displaced_path was measured (map_to_sculpt: its vertices to the sculpt;
  // sculpt_to_map: the sculpt's vertices to it); nothing else is.
  bool displaced_mesh = false;
  double diagonal = 0;
  std::size_t ptex_faces = 0;
  bool map_vector = false;                        // a vector map (else scalar)
  VectorSpace map_space = VectorSpace::kTangent;  // of a vector map
  int samples_per_face_min = 0, samples_per_face_max = 0;
  bool measured_distances = false;
  double distance_tolerance = 0;  // tau of the distances in tolerances (0: none known)
  // A UV-space map: the Ptex faces with points whose UVs no tile holds (read as 0), ascending.
  std::vector<int> uv_faces_without_tile;
  ErrorStats map_to_sculpt;  // displaced limit surface -> nearest sculpt point
  ErrorStats sculpt_to_map;  // sculpt vertices -> nearest point of the displaced surface
  bool measured_truth = false;
  int truth_version = 0;  // of the truth file: 1, 2 or 3 (with D)
  // What `truth` measures at every record, in object units, by the kinds of map and truth:
  //   "|map - h|"      scalar map, truth without D (versions 1, 2)
  //   "|map N - D|"    scalar map, truth with D: the normal part from the record's h,
  //                    sqrt((map - h)^2 + |D - h N|^2), so a map of a vector pattern fails
  //   "|D_map - D|"    vector map, truth with D
  //   "|D_map.N - h|"  vector map, truth without D: its normal part only
  // N and the frame of a vector map are the limit surface's at the record's (face, u, v).
  std::string truth_quantity;
  ErrorStats truth;  // that error at every truth record
  // The mean signed error of the normal part: map - h, or (D_map - D).N.
  double truth_signed_mean = 0;
  double truth_tolerance = 0;               // tau of the truth bounds (0: they were not checked)
  bool truth_local_checked = false;         // the per-record bound (a version-2 or -3 truth file)
  std::size_t truth_over_bound = 0;         // records whose error exceeds k tau + 2 e_v
  double truth_worst_ratio = 0;             // the largest error / (k tau + 2 e_v)
  double truth_local_tolerance_factor = 0;  // k
  std::size_t truth_unbounded = 0;  // records near folded sculpt faces (e_v infinite): unchecked
  ErrorStats truth_local_error;     // e_v over the bounded records: what the sculpt's facets add
  struct TruthRecord {
    std::size_t index = 0;
    int face = -1;
    // h and map: the normal parts (the map's value, or D_map.N of a vector map).
    float u = 0, v = 0, h = 0, map = 0, local_error = 0;
    // With a version-3 truth: D and the map's displacement in object space (map N for a
    // scalar map).
    bool vector = false;
    float d[3] = {0, 0, 0}, map_d[3] = {0, 0, 0};
  };
  TruthRecord truth_worst;                          // the record of truth_worst_ratio
  double truth_rms_limit = 0, truth_p99_limit = 0;  // 0: not checked
  struct WorstFace {
    int face = -1;
    double max = 0;
  };
  std::vector<WorstFace> worst_faces;  // by map -> sculpt max, at most 10
  // Per Ptex face, empty when not measured (`dispex view --verify` colours faces by them; NaN,
  // null in the JSON, for a face without samples or records): the largest map -> sculpt
  // distance of its samples, and the largest truth error (truth_quantity) at its records.
  std::vector<double> face_map_to_sculpt_max, face_truth_max;
  // Steps at shared edges, object units, one per point (include/dispex/ptex_sampler.h for
  // the readers): the per-face reader (clamped at the face's border) and the reference
  // filter across faces. Of a vector map, the length of the step of D in object space: each
  // texel converted to object space with the frame at its centre (exact for the values a map
  // stores), then both readers on the x, y and z fields (edges_object_space).
  bool measured_edges = false;
  bool edges_object_space = false;
  std::size_t edges = 0;         // shared edges between faces with a surface
  std::size_t crease_edges = 0;  // of those, on infinitely sharp creases: not measured
  // Of those, beside faces the map lists as discontinuous (dispex:discontinuous_faces: filled
  // holes, other-sheet hits): not measured.
  std::size_t discontinuous_edges = 0;
  ErrorStats edge_per_face, edge_across_faces;
  double edge_tolerance = 0;  // tau the steps are checked against (0: not checked)
  double edge_max_limit = 0, edge_p99_limit = 0;  // object units; 0: not checked
  struct WorstEdge {
    int face = -1, edge = 0, neighbour = -1;
    double t = 0;             // along the face's edge, counter-clockwise
    double step = 0;          // object units
    const char* reader = "";  // "per-face" or "across-faces"
  };
  std::vector<WorstEdge> worst_edges;  // largest step first, at most 10
  // From the map's own meta data, when dispex wrote it.
  std::int64_t map_misses = -1, map_holes_filled = -1, map_faces_filled_from_neighbours = -1;
  double map_tolerance = 0;
  bool passed = true;
  std::string failure;                // why it did not pass
  std::vector<std::string> warnings;  // one line each (tags of the base that were ignored)
  double seconds = 0;
};

// Re-displaces the base limit surface with the map (read bilinearly, as a renderer would: P + h
// N, or P + D for a vector map) and measures it against the sculpt both ways, and/or against a
// truth file; measures the steps at shared face edges always. Fails, naming the map, for a map
// that is neither scalar nor vector (DisplacementMapSpace).
StatusOr<VerifyReport> Verify(const VerifyOptions& options);

std::string VerifyReportJson(const VerifyReport& report);
std::string VerifyReportSummary(const VerifyReport& report);

}  // namespace dispex
