// dispex::Extract: a base cage and its sculpt in, a Ptex displacement map out.
//
// For every Ptex face of the base's Catmull-Clark limit surface: an oversampled grid of
// limit points and unit normals, rays along +n and -n into the sculpt, signed distances,
// holes filled, the fewest texels that keep the error within the tolerance (DCT analysis),
// and the face's compressed Ptex block. Faces run in parallel and each face's buffers live
// only while it is processed. The output file is byte-identical for the same inputs and
// options whatever the thread count, and appears only when complete.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/progress.h"
#include "dispex/ptex.h"
#include "dispex/spectral.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "dispex/vector_space.h"

namespace dispex {

// What to do with samples whose rays missed the sculpt.
enum class HolePolicy : std::uint8_t {
  kFill,  // interpolate from the face's valid samples (pull-push), or from neighbouring faces
  kFail,  // any miss is an error
  kZero,  // write 0
};
std::string_view HolePolicyName(HolePolicy policy);  // "fill", "fail", "zero"
StatusOr<HolePolicy> ParseHolePolicy(std::string_view name);

// Which readers the map is made watertight for: where two Ptex faces meet, the values a
// renderer reads on either side differ by at most the tolerance (docs/ACCURACY.md,
// "Watertight edges"), except at edges where the displacement itself jumps.
enum class WatertightEdges : std::uint8_t {
  // The reference Ptex filter across faces (what renderers built on the Ptex library read):
  // resolutions raised where neighbours of different resolution would step. Costs under 1%
  // of the texels on the maps measured (docs/BENCHMARKS.md).
  kFilter,
  // Also per-face bilinear reading (readers that do not filter across faces): edge texels
  // pinned to the edge and resolutions raised until faces read on their own meet. Costs
  // several times the texels on sculpts detailed at their own resolution.
  kAll,
  kOff,  // neither: each face within the tolerance of its own samples only
};
std::string_view WatertightEdgesName(WatertightEdges mode);  // "all", "filter", "off"
StatusOr<WatertightEdges> ParseWatertightEdges(std::string_view name);

// Where a map's values come from.
enum class ExtractMethod : std::uint8_t {
  // kInterpolate when the sculpt is the base refined (MatchRefinedSculpt), else kRays.
  kAuto,
  kRays,  // a BVH of the whole sculpt: rays along the limit normal
  // Rays through the correspondence: each sample's rays against the sculpt quads in the rings
  // of cells around it, the few it cannot decide by a BVH built afterwards (docs/
  // ARCHITECTURE.md); the map follows the sculpt's flat quads. Vector maps: the sculpt's
  // quads read bilinearly at each sample minus the limit point. An error when the sculpt is
  // not the base refined.
  kMapping,
  // The sculpt's vertex displacements (each vertex minus the limit point it sits over)
  // interpolated bilinearly over the correspondence's cells, no rays (docs/ACCURACY.md,
  // "Interpolated vertex displacements"): exact at the sculpt's vertices, what a renderer's
  // subdivided base displaced at its vertices shows. A scalar map holds their part along the
  // limit normal. An error when the sculpt is not the base refined.
  kInterpolate,
};
std::string_view ExtractMethodName(
    ExtractMethod method);  // "auto", "rays", "mapping", "interpolate"
StatusOr<ExtractMethod> ParseExtractMethod(std::string_view name);

// What a farm shard keeps of the sculpt (ExtractOptions::shard_sculpt).
enum class ShardSculpt : std::uint8_t { kWhole, kPart };
std::string_view ShardSculptName(ShardSculpt s);  // "whole", "part"
StatusOr<ShardSculpt> ParseShardSculpt(std::string_view name);

struct ExtractOptions {
  std::string base_path;
  std::string sculpt_path;
  std::string output_path;
  // Meshes already in memory (a program that holds them, e.g. the Python module), used instead
  // of reading base_path / sculpt_path, which then only name them: in messages, the report and
  // the map's dispex:base / dispex:sculpt meta data ("base" / "sculpt" when empty). Each is
  // checked as the readers check a file's (CheckMeshArrays; its `source` names it in those
  // errors) and fingerprinted by its content as a file's mesh is, so the map is the one the
  // same mesh read from a file of that name gives, and incremental runs compare it the same way.
  // Extract only: ExtractAsset reads its files.
  std::shared_ptr<const Mesh> base_mesh, sculpt_mesh;

  // Samples per side of each Ptex face's grid: a power of two 4..512, or 0 for automatic
  // (from the sculpt's density over each face: a face covered by k sculpt quads is sampled at
  // the power of two >= 2 sqrt(k), i.e. 2^(L+1) for a level-L subdivided sculpt), capped by
  // max_oversample.
  int oversample = 0;
  int max_oversample = 128;
  int min_oversample = 4;

  SearchDistanceSpec search_distance;  // auto, absolute, or a fraction of the base diagonal
  HitPolicy ray_policy = HitPolicy::kNearest;
  ExtractMethod method = ExtractMethod::kAuto;

  // Largest allowed error of a stored face against its samples, in object units; 0: automatic,
  // tolerance_fraction times the sculpt's median edge length.
  double tolerance = 0;
  double tolerance_fraction = 0.05;
  ResolutionRule resolution_rule = ResolutionRule::kErrorBound;
  double nonzero_threshold = 0;  // for ResolutionRule::kNonzero
  int fixed_ulog2 = 6;           // for ResolutionRule::kFixed
  int fixed_vlog2 = 6;
  // With ResolutionRule::kErrorBound (the other rules fix the resolution): raise resolutions
  // until shared edges meet within the tolerance under the readers named.
  WatertightEdges watertight = WatertightEdges::kFilter;

  PtexDataType data_type = PtexDataType::kFloat;  // kFloat or kHalf
  int compression_level = -1;                     // -1: the writer's default
  HolePolicy holes = HolePolicy::kFill;
  // The largest fraction of samples (over all faces) that may still miss the sculpt after the
  // second search; above it the extraction fails and writes nothing, since the map would be
  // mostly invented by hole filling (the sculpt covers the base only in part, or the meshes
  // are not aligned). 1 turns the check off.
  double max_miss_fraction = 0.05;
  BuildQuality bvh_quality = BuildQuality::kLow;  // measured: same ray speed, a third of the build
  std::string embree_isa;  // TracerOptions::isa: "" = $DISPEX_EMBREE_ISA, else Embree's choice

  int threads = 0;        // 0: all cores; the output does not depend on it
  bool progress = false;  // draw a progress bar on stderr
  // When given, counts the Ptex faces done of the total (drawn or not); must outlive Extract.
  ProgressCounter* progress_counter = nullptr;

  // Refuse, before the work starts, an extraction estimated to need more memory than this
  // (bytes; 0: the memory the machine has available). See EstimateExtractMemory.
  std::uint64_t max_memory = 0;

  // Refuse inputs that do not belong together (docs/ROBUSTNESS.md, "Inputs that do not belong
  // together"): a sculpt with fewer faces than its base (the two swapped), and a sculpt moved,
  // scaled or turned against its base as a whole (extract/input_checks.h). Off: extract them
  // anyway, for a displacement that is meant.
  bool check_inputs = true;

  // Re-use the map already at output_path (docs/INCREMENTAL.md): when the inputs and options
  // are those it was made from, it is left as it is (not rewritten); otherwise only the faces
  // whose key changed are extracted again and the others copied from it. The result is the
  // same file a full extraction writes. A map that is missing, unreadable, or written by
  // another version is not re-used (a warning says why).
  bool incremental = false;
  // Where incremental runs keep what the next run after an edit can re-use: the sculpt's
  // half-edge adjacency, which depends on its faces only (MatchOptions::cache_dir). "":
  // $XDG_CACHE_HOME/dispex, else $HOME/.cache/dispex; "off": nothing kept. Only speed depends
  // on it.
  std::string cache_dir;

  // Stop once the plan is made (ExtractReport::plan: which faces would run, from where the
  // others come, the method and tracer): the inputs are read, matched and keyed, no face is
  // traced and nothing is written.
  bool plan_only = false;

  // Vector displacement (docs/VECTOR.md): a 3-channel map of D = sculpt - limit surface in this
  // space (include/dispex/vector_space.h), the sculpt read exactly at each sample through its
  // correspondence with the base -- it must be the base refined (MatchRefinedSculpt) -- with
  // no rays. Empty: the scalar map along the limit normal. The search distance, when given,
  // bounds how far a sculpt vertex may lie from its point on the limit surface
  // (MatchOptions::max_offset); ray and hole options do not apply. Watertight edges are held
  // for D's length in object space (docs/VECTOR.md, "Face borders").
  std::optional<VectorSpace> vector;

  // UV-space maps beside the Ptex map (docs/UV_MAPS.md): when not empty, one OpenEXR file per
  // UDIM tile the base's UVs touch, uv_maps_dir/<shape>.<UDIM>.exr (<shape>: the asset's shape
  // name, else the output's file name without extension), uv_resolution texels per side,
  // data_type's precision. Each texel centre inside a UV face is extracted where it lies on the
  // limit surface (the cage's UVs interpolated face-varying linearly, include/dispex/
  // uv_charts.h) with the same rays, search distance and policy as the Ptex map; texels outside
  // every UV face (and those whose rays miss) are filled by dilation, uv_padding rings of
  // texels. The base needs UVs on every face. A vector map (`vector`) must be object space: its
  // tiles hold D's x, y, z, read at each texel through the sculpt's correspondence.
  std::string uv_maps_dir;
  int uv_resolution = 1024;  // 1..16384
  int uv_padding = 16;       // >= 0

  // A farm shard (docs/FARM.md): with shard_count > 0, only the shard_index-th (1..shard_count)
  // of shard_count runs of Ptex faces, balanced by estimated cost (samples and sculpt faces
  // within reach), is extracted: output_path receives a part holding their first pass, for
  // MergeShards. The parts of every shard merge into the map this extraction without shards
  // writes, byte for byte. Scalar maps of one shape only.
  int shard_index = 0;
  int shard_count = 0;
  // What a shard keeps of the sculpt. kWhole: all of it, read, matched and traced (its memory
  // does not fall with shard_count). kPart: a shard that traces keeps the sculpt within reach
  // of its faces (its BVH's part; the rest is released once the faces' keys are made) and
  // estimates an automatic search distance over the sculpt in parts, one BVH at a time, so its
  // memory falls with shard_count; through the correspondence (which matches the whole sculpt)
  // it traces only within reach whatever this option says. Hits do not depend on the BVH's
  // extent at shared edges, vertices and folds (the tie rule, dispex/trace.h); only where two
  // sheets of the sculpt that share no vertex cross within float rounding of each other on a
  // sample's line may a part's hit differ from the whole's (docs/FARM.md). Not an option of
  // the map: it is not recorded, and a merge does not check it.
  ShardSculpt shard_sculpt = ShardSculpt::kWhole;
};

// The face table of every map of `surface`, taken from the limit surface (OpenSubdiv's Ptex
// numbering and adjacency are the one source of both, so a map's faces are the faces that
// were sampled): one PtexFaceInfo per Ptex face with neighbours and shared edges as
// Far::PtexIndices gives them (-1 / 0 where there is none), `subface` for the quads an n-gon
// is split into, resolution 1x1 (each face's own is set when it is written).
std::vector<PtexFaceInfo> PtexFaceTable(const LimitSurface& surface);

// What a map records of each mesh it was made from (dispex:base_fingerprint,
// dispex:sculpt_fingerprint): "xxh3-128:" and the hash of everything the mesh as read holds that
// can change a map (positions, faces, subdivision tags; not its groups, UVs or file name).
std::string MeshFingerprint(const Mesh& mesh);

// Checks ranges and combinations, and that the outputs can be written (CheckOutputFile,
// CheckMapName), before any work; the message names the option. Code kInvalidArgument, or
// kOutput for an output that cannot be written.
Status ValidateExtractOptions(const ExtractOptions& options);

// A memory size: "8G", "512M", "300K" or a number of bytes (ExtractOptions::max_memory).
StatusOr<std::uint64_t> ParseByteSize(const std::string& text);
// "1.50 GiB", "20.0 MiB", "512.0 KiB": a size for messages.
std::string MemorySize(std::uint64_t bytes);

// A map's name whose extension says another format (map.exr, map.png, map.obj) is refused.
Status CheckMapName(const std::string& path);

// ---- Options by name ---------------------------------------------------------------------------

// The kind of value an option takes, as JSON (a manifest's value; a program's value turned
// into JSON): what a program checks before it hands a value over.
enum class OptionKind : std::uint8_t {
  kInteger,        // 64
  kNumber,         // 0.001 (an integer too)
  kBool,           // true
  kText,           // "64x64"
  kPath,           // "maps/uv": a file or folder
  kChoice,         // one of the names ExtractOptionSpec::values lists: "fill"
  kIntegerOrAuto,  // 64 or "auto"
  kSize,           // 8589934592 or "8G"
  kDistance,       // 0.05, "auto" or "2%"
};

// One extract option set by name, declared once (src/extract/io/option_table.cpp): the field
// and flag, the value it takes, and how `dispex extract` offers it (tools/cmd_extract.cpp makes
// every one of its flags and their --help lines from this table).
struct ExtractOptionSpec {
  std::string_view name;  // the ExtractOptions field: manifests, Python keywords, messages
  std::string_view flag;  // the command line's flag
  OptionKind kind;
  std::string_view values;  // what it takes, in words: "fill, fail or zero"
  bool in_manifest;         // false: set for one run only (threads, incremental, shard)
  // Recorded in the map (dispex:options) and so in its inputs key: a change re-extracts an
  // incremental run's faces. false: how the run goes, not what the map holds (threads,
  // memory, checks, where other outputs go).
  bool in_map = false;
  // The flag's line in `dispex extract --help` (one line: what it does, how to spell it).
  std::string_view help;
  // The default as the command line spells it ("auto", "128", "64x64"), which --help shows
  // after the value's type; empty: none is shown (none given, or the help says it). A kBool
  // option's flag takes no value and gives the opposite of this: "true" for check_inputs,
  // whose flag --no-input-checks turns it off.
  std::string_view default_text = {};
  // 0 is the automatic value (tolerance, oversample). The command line gets it by leaving the
  // flag out (or with 'auto'), so its text refuses 0 and below rather than take them silently.
  bool zero_is_auto = false;
};
std::span<const ExtractOptionSpec> ExtractOptionSpecs();

// The names SetExtractOption takes, comma-separated (for messages).
std::string ExtractOptionNames();

// Sets one option by its ExtractOptions field name from a value as a manifest gives it
// (ReadExtractManifest, docs/SHAPES.md) -- JSON text: "0.001", "\"auto\"", "\"64x64\"" --,
// for a program that takes options by name (the Python module). Errors (code
// kInvalidArgument) start with the name: "tolerance: \"x\" is not a number", "colour: unknown
// option (known: ...)".
Status SetExtractOption(ExtractOptions& options, const std::string& name,
                        const std::string& json_value);

// Sets one option by its field name from the text its command-line flag takes ("0.001",
// "auto", "2%", "64x32", "8G", "tangent"; "true" or "false" for a kBool option), through the
// same setter as SetExtractOption: the text is read as the option's kind reads it (kInteger: a
// whole decimal integer, kIntegerOrAuto: one or "auto", kNumber: a number, kBool: true or
// false; the other kinds take it as it is), and refused at 0 and below where zero_is_auto.
// Errors (code kInvalidArgument) say what is wrong with the value, leaving the option to be
// named by the caller, which knows how it was given ("x is not a number"; the command line
// prints "--tolerance: x is not a number"); a name not in the table: "unknown option 'colour'
// (known: ...)".
Status SetExtractOptionText(ExtractOptions& options, std::string_view name,
                            const std::string& text);

// What one map's extraction does, decided before its faces are traced, each part by the stage
// that can decide it (the method once the sculpt is matched, the faces once their keys are
// known); in the report ("plan") and, with ExtractOptions::plan_only, all a run does.
struct ExtractPlan {
  enum class Output : std::uint8_t {
    kMap,        // the map at output_path (and its UV-space tiles)
    kShardPart,  // a farm shard's part (ExtractOptions::shard_count)
    kUpToDate,   // nothing: the map at output_path was made from these inputs (incremental)
  };
  enum class Tracer : std::uint8_t {
    kNone,         // no BVH: the sculpt read through its correspondence (mapping, interpolate)
    kWholeSculpt,  // a BVH of the whole sculpt
    kWithinReach,  // a BVH of the sculpt within reach of the faces that run (and their rings)
    // A BVH of the sculpt within reach of one run of the faces at a time, sculpt_parts runs:
    // the whole sculpt's does not fit in max_memory (the map is the same).
    kInParts,
  };
  Output output = Output::kMap;
  int channels = 1;                             // 3: a vector map
  ExtractMethod method = ExtractMethod::kAuto;  // the method that runs (kAuto: not chosen yet)
  Tracer tracer = Tracer::kWholeSculpt;
  // Where the faces that do not run get their texels: "" (all run), the previous map's path
  // (incremental), or "N shard parts" (a merge).
  std::string faces_from;
  std::string redo_reason;  // why faces run again (incremental): ExtractReport::incremental
  // Ptex faces: all of them; those extracted in this run; copied from faces_from; another
  // shard's (a shard part); holes of the base (no surface, written as 0). -1: not planned yet.
  std::int64_t faces = 0, faces_run = -1, faces_copied = -1, faces_elsewhere = 0, hole_faces = 0;
  bool uv_maps = false;  // UV-space tiles written after the map
  // The memory the plan is made to fit (max_memory, or what the machine has available) and
  // what it is estimated to need at its peak (bytes); the runs of kInParts (0 otherwise).
  std::uint64_t memory_limit = 0, memory_estimate = 0;
  int sculpt_parts = 0;
  // kWholeSculpt built compact at medium quality: the BVH at the asked quality does not fit in
  // max_memory (the map is the same).
  bool compact_bvh = false;
  // The parts the sculpt's automatic search distance is estimated in, one BVH at a time (0: by
  // one BVH of the whole sculpt, or through the correspondence, or none to estimate).
  int search_estimate_parts = 0;
};
std::string_view ExtractPlanOutputName(
    ExtractPlan::Output output);  // "map", "shard part", "up to date"
std::string_view ExtractPlanTracerName(
    ExtractPlan::Tracer tracer);  // "none", "whole sculpt", "within reach", "in parts"
// The plan in a few lines for people ("plan: a map (scalar), method mapping, BVH: none ...").
std::string ExtractPlanSummary(const ExtractPlan& plan);

// What one extraction did, grouped as its JSON report (ExtractReportJson) is.
struct ExtractReport {
  std::string version;
  std::string shape;  // the shape's name when extracted as part of an asset (ExtractAsset)
  ExtractPlan plan;
  ExtractOptions options;  // as given
  std::vector<std::string> warnings;
  std::uint64_t peak_rss_bytes = 0;
  std::string tracer;  // TracerStats::backend: Embree version, ISA, build

  struct Inputs {
    std::string base_path, sculpt_path;
    std::string base_fingerprint, sculpt_fingerprint;
    std::size_t base_vertices = 0, base_faces = 0, ptex_faces = 0, hole_faces = 0;
    std::size_t sculpt_vertices = 0, sculpt_faces = 0;
    int inf_sharp_edges = 0;
    double base_diagonal = 0;
    double sculpt_median_edge = 0;
  } inputs;

  struct Output {
    std::string path;
    std::uint64_t bytes = 0;  // of the map
  } output;

  // Automatic values resolved, and the threads used.
  struct Settings {
    double tolerance = 0;
    bool tolerance_auto = false;
    double search_distance = 0;
    bool search_distance_auto = false;
    SearchDistanceEstimate search_estimate;  // when automatic
    int threads = 0;
  } settings;

  // Phases, wall seconds; then, within sample+trace, CPU time of the worker threads (each
  // thread's own clock, summed): limit evaluation, rays, spectral analysis, compression and
  // writing.
  struct Times {
    double read_base = 0, read_sculpt = 0, topology = 0, match = 0, bvh = 0, search = 0, keys = 0,
           sample_trace = 0, write = 0, uv_maps = 0, total = 0;
    double cpu_limit = 0, cpu_trace = 0, cpu_spectral = 0, cpu_compress = 0;
  } times;

  // The method that ran and, when the correspondence was looked for, the match: the sculpt is
  // the base refined `levels` times (-1 when not matched; `reason` says why), its vertices up to
  // max_offset (rms rms_offset) from their points on the limit surface.
  struct Method {
    ExtractMethod used = ExtractMethod::kRays;  // kRays, kMapping or kInterpolate
    std::string reason;
    int levels = -1;
    double max_offset = 0, rms_offset = 0;
    // Through the correspondence with rays (kMapping): the longest hit kept, twice the largest
    // vertex offset the match measured (over the vertices it checks: all of them on grids up to
    // 8 x 8) plus the sculpt's median edge; a hit beyond it is another sheet of the sculpt and
    // counts as a miss. The search distances are cut to it. 0: none.
    double sheet_bound = 0;
    // Samples the mapping could not decide, answered by a BVH of the sculpt within their
    // reach, and the Ptex faces they are in (of the faces extracted in this run).
    std::int64_t fallback_samples = 0, fallback_faces = 0;
    // The sculpt's adjacency was read from the cache folder (ExtractOptions::cache_dir), or the
    // match itself kept there was still this sculpt's (MatchOptions::cache_dir).
    bool adjacency_cached = false;
    bool labelling_cached = false;
  } method;

  // Sampling and rays.
  struct Sampling {
    std::array<std::int64_t, 10> oversample_faces{};  // faces by log2 of the samples per side
    // Automatic oversampling's rule: the L of a sculpt that is the base subdivided L times, or
    // -1 when the sculpt is measured by density (area) or oversampling is fixed.
    int oversample_subdivision_level = -1;
    std::int64_t samples = 0;
    std::uint64_t rays_cast = 0;
    std::int64_t hits_positive = 0, hits_negative = 0;
    // Hits on sculpt faces that face against the limit normal: the sculpt folds there or the
    // ray met another sheet (|displacement| x curvature >= 1, thin parts).
    std::int64_t hits_opposed = 0;
    // With an automatic search distance, samples that miss are searched again this far (0
    // when the distance was given).
    double retry_search_distance = 0;
    std::int64_t misses_recovered = 0;  // samples that hit on that second search
    std::int64_t misses = 0;            // samples whose rays found nothing
    double miss_fraction = 0;           // misses / samples
    std::int64_t holes_filled = 0;      // of those, filled within their face
    std::int64_t faces_with_misses = 0;
    std::int64_t faces_filled_from_neighbours = 0;
    std::int64_t faces_unreachable = 0;  // missed entirely, no neighbour to fill from: 0 written
    std::int64_t fallback_normals = 0;
  } sampling;

  SpectralTotals spectral;

  // Watertight edges (rule kOff when the option is off or the rule is not kErrorBound). Steps
  // are the largest over every texel breakpoint of every shared edge (MeasurePtexEdgeSteps; of
  // a vector map, the length of D's step in object space) once the map is final, in object
  // units.
  struct Edges {
    WatertightEdges rule = WatertightEdges::kOff;
    std::int64_t rounds = 0;         // rounds of raising resolutions
    std::int64_t raised_faces = 0;   // faces whose resolution the edges raised
    std::int64_t texels_before = 0;  // texels written had no edge been raised
    std::int64_t shared = 0;         // between two faces with a surface
    std::int64_t sharp = 0;          // on infinitely sharp creases: not held
    // Edges beside faces whose displacement may jump -- samples filled over holes of the
    // sculpt, hits on another sheet, or no hit at all -- not held; those faces, by id (stored
    // in the map as dispex:discontinuous_faces for verify).
    std::int64_t discontinuous = 0;
    std::vector<std::int32_t> discontinuous_faces;
    // Held edges still over the tolerance: the samples are too coarse, or the displacement
    // jumps there (another sheet, a filled hole), so raising the resolution did not bring them
    // down.
    std::int64_t over = 0;
    // Largest over held edges; per face only with WatertightEdges::kAll (0 otherwise).
    double step_per_face = 0, step_across_faces = 0;
  } edges;

  // The map's values: along the normal (min, max, rms); a vector map's space (empty for a
  // scalar map), its largest |D| and largest part across the normal (min, max hold D . N, rms
  // |D|).
  struct Displacement {
    double min = 0, max = 0, rms = 0;
    std::string vector_space;
    double length_max = 0, tangential_max = 0;
  } displacement;

  // Incremental extraction (ExtractOptions::incremental) and the faces of a shard part.
  struct Incremental {
    std::string inputs_key;  // of the inputs and options: the map stores it as dispex:inputs_key
    bool unchanged = false;  // the map was made from the same inputs and options: not rewritten
    std::int64_t faces_copied = 0;     // from the previous map (or a shard's part)
    std::int64_t faces_extracted = 0;  // Ptex faces with a surface that were not copied
    // Of the faces copied, those the watertight edges extracted again: a neighbour's edge
    // changed.
    std::int64_t faces_copied_redone = 0;
    // With watertight edges: the shared edges whose first measurement was copied from the
    // previous map (no face around them changed) instead of measured again.
    std::int64_t edges_copied = 0;
    // Interpolated: the Ptex faces whose key of what they read of the sculpt was taken from
    // cache_dir (none of those sculpt vertices moved since it was kept) instead of gathered
    // again; -1 when nothing was kept for these grids.
    std::int64_t fields_kept = -1;
    // Why faces were extracted again: "no previous map", the previous map's notice, or what
    // changed ("base, sculpt, options: tolerance").
    std::string redo_reason;
    // With a given search distance: the Ptex faces whose reach the BVH holds when it holds
    // only part of the sculpt (docs/INCREMENTAL.md); 0 when it holds all of it.
    std::int64_t tracer_faces = 0;
    // An automatic search distance through rays, updated from the rays of the run before (kept
    // in cache_dir): the long rays cast again, of search_rays; -1 when it was not updated.
    std::int64_t search_rays_recast = -1, search_rays = 0;
  } incremental;

  // UV-space maps (ExtractOptions::uv_maps_dir): the files written, texel centres inside a UV
  // face, those of them whose rays missed (filled by dilation as if outside), texel centres in
  // two faces and the Ptex faces involved (UvRaster::overlap_texels), faces whose UVs leave the
  // UDIM range.
  struct UvMaps {
    std::vector<std::string> paths;
    std::int64_t texels_inside = 0, texels_missed = 0, overlap_texels = 0;
    std::vector<std::int32_t> overlap_faces, faces_outside_udim;
    // Incremental: the faces whose texels were copied from the tiles of the run before.
    std::int64_t faces_copied = 0;
  } uv;

  // A shard (ExtractOptions::shard_count > 0): the run [begin, end) of the shard order it
  // extracted (the Ptex faces along a Z-order curve of their centres on the base:
  // docs/FARM.md), and their estimated cost against the whole map's. A merge (MergeShards):
  // the parts merged.
  struct Shard {
    std::int64_t begin = 0, end = 0;
    double cost_fraction = 0;
    std::int64_t parts_merged = 0;
  } shard;
};

// Runs the whole pipeline. Errors (bad inputs, nothing hit, a miss under HolePolicy::kFail,
// cancellation) leave no output file. A base made of several shapes (ExtractAsset) is an error
// that names them.
StatusOr<ExtractReport> Extract(const ExtractOptions& options);

// ---- Farm shards (docs/FARM.md) --------------------------------------------------------------

struct MergeOptions {
  // The parts written by the shards of one extraction (ExtractOptions::shard_count), in any
  // order. They name the base, sculpt and options they were made from; merging reads those
  // files again (the stages after each face's first pass cross faces).
  std::vector<std::string> parts;
  std::string output_path;
  int threads = 0;
  bool progress = false;
  ProgressCounter* progress_counter = nullptr;  // as ExtractOptions::progress_counter
  std::uint64_t max_memory = 0;                 // as ExtractOptions::max_memory
};

// The map the extraction without shards writes, byte for byte, from the parts of all its
// shards. Fails, writing nothing, in one line naming the part when a shard is missing or given
// twice, or when parts differ in version, inputs (fingerprints), options or shard count.
StatusOr<ExtractReport> MergeShards(const MergeOptions& options);

// "I/N" (1 <= I <= N) as a shard's index and count.
Status ParseShard(std::string_view text, int& index, int& count);

// What a shard of `options` keeps of the sculpt within `node_memory` bytes (a farm node's), from
// the sculpt file's counts (CountMeshElements) and the estimates max_memory plans with: kWhole
// when one extraction fits (a BVH of the whole sculpt where it may trace -- method kRays, or
// kAuto should the match fail -- at the asked quality, else built compact at medium quality as
// the shard's own memory plan does; where it does not trace, the correspondence), else kPart
// (each shard traces only the sculpt within reach of its faces, in parts when even that does
// not fit). kOverBudget,
// naming the sculpt, when not even reading it, its arrays, its correspondence (where matched)
// and the output fit.
struct ShardMemoryPlan {
  ShardSculpt shard_sculpt = ShardSculpt::kWhole;
  std::uint64_t whole_bytes = 0;    // one extraction at its peak
  std::uint64_t compact_bytes = 0;  // the same with the BVH built compact (0: not estimated)
  bool compact_bvh = false;         // kWhole only with the sculpt's BVH built compact
  std::uint64_t floor_bytes = 0;    // any shard: reading, the arrays, the correspondence, output
};
StatusOr<ShardMemoryPlan> PlanShardMemory(const ExtractOptions& options, std::uint64_t node_memory);

// ---- Batches of assets (docs/FARM.md) ----------------------------------------------------------

// One map of a batch: options with the base, sculpt and output path set.
struct BatchAsset {
  std::string name;
  ExtractOptions options;
};

// A batch manifest (JSON): {"options": {...}, "assets": [{"name": "spot", "base": "spot.obj",
// "sculpt": "spot_sculpt.obj", "output_dir": "maps", "options": {"tolerance": 0.001}}, ...]}.
// Each asset's map is output_dir/<name>.ptx; names are letters, digits, '_', '-' and '.'
// (they name files and farm jobs) and unique. Paths are relative to the manifest's folder;
// options as in ReadExtractManifest, over `defaults`, an asset's over the manifest's. Errors
// name the file and the entry.
StatusOr<std::vector<BatchAsset>> ReadBatchManifest(const std::string& path,
                                                    const ExtractOptions& defaults);

// ---- Assets of several shapes ---------------------------------------------------------------

// A shape of an asset named in a manifest: the files that hold it and its own options.
struct AssetShapeSpec {
  std::string name;  // the shape's o/g group name in both files (any name for single-shape files)
  std::string base_path, sculpt_path;
  ExtractOptions options;  // paths and output ignored
};

struct ExtractAssetOptions {
  // Every option for every shape; base_path and sculpt_path are the asset's files (unless
  // `manifest` is given); output_path is not used.
  ExtractOptions options;
  // The maps: output_dir/<file name>.ptx, file names from ShapeFileNames (include/dispex/shapes.h).
  std::string output_dir;
  // Only these shapes of the base (empty: all of them).
  std::vector<std::string> shapes;
  // When not empty, these shapes, each from its own files with its own options, instead of the
  // shapes of options.base_path and options.sculpt_path.
  std::vector<AssetShapeSpec> manifest;
};

struct AssetReport {
  std::string version;
  std::string output_dir;
  struct Shape {
    std::string name;
    std::string file;  // the map's path
    ExtractReport report;
  };
  std::vector<Shape> shapes;  // in the base's (or the manifest's) order
  std::vector<std::string> warnings;
  double t_read = 0, t_total = 0;  // seconds: reading the files, and everything
  std::uint64_t peak_rss_bytes = 0;
};

// One map per shape of an asset (OBJ o/g groups; a PLY is one shape): each base shape paired
// by name with the sculpt's shape (MatchShapes), so that its rays hit only that sculpt shape,
// and extracted as Extract would extract it alone. Each file is read once; shapes run in
// parallel; every map is the same whatever the order or thread count. With
// options.incremental, each shape's map is re-used as Extract re-uses it. On an error, the
// maps of the shapes before it in the base's order may have been written (each whole).
StatusOr<AssetReport> ExtractAsset(const ExtractAssetOptions& options);

// A manifest (JSON, docs/SHAPES.md) of shapes spread over several files, each with its own
// options: {"output_dir": "maps", "options": {...}, "shapes": [{"name": "head", "base":
// "head.obj", "sculpt": "head_sculpt.obj", "options": {"tolerance": 0.001}}, ...]}. Paths are
// relative to the manifest's folder; options (named as ExtractOptions' fields, values as the
// command line takes them) apply over `defaults`, shape options over the manifest's. Errors
// name the file and the entry.
StatusOr<ExtractAssetOptions> ReadExtractManifest(const std::string& path,
                                                  const ExtractAssetOptions& defaults);

std::string AssetReportJson(const AssetReport& report);
std::string AssetReportSummary(const AssetReport& report);

// The report as JSON (pretty-printed) and as a short human summary.
std::string ExtractReportJson(const ExtractReport& report);
std::string ExtractReportSummary(const ExtractReport& report);

}  // namespace dispex
