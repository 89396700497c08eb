#include "extract/mapping/extract_mapping.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <utility>
#include <vector>

#include "core/system.h"
#include "dispex/cancel.h"
#include "extract/incremental/face_keys.h"
#include "extract/parallel_errors.h"

namespace dispex::extract {

StatusOr<SculptCorrespondence> MatchSculpt(const ExtractOptions& options, MatchOptions match,
                                           ExtractInputs& inputs, ExtractReport& report) {
  match.accept_reversed = true;
  if (options.incremental) match.cache_dir = CacheFolder(options);
  StatusOr<SculptCorrespondence> correspondence =
      MatchRefinedSculpt(inputs.surface, inputs.sculpt, match);
  if (correspondence.ok()) {
    report.method.adjacency_cached = correspondence->adjacency_from_cache;
    report.method.labelling_cached = correspondence->labelling_from_cache;
  }
  if (correspondence.ok() && correspondence->reversed) {
    ReverseWinding(inputs.sculpt);
    report.warnings.push_back(fmt::format(
        "{}: every face winds the other way from the base's (flipped normals); it is read with "
        "the winding reversed",
        inputs.sculpt.source));
  }
  return correspondence;
}

std::string CacheFolder(const ExtractOptions& options) {
  if (options.cache_dir == "off") return {};
  if (!options.cache_dir.empty()) return options.cache_dir;
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg != nullptr && *xdg == '/') return (std::filesystem::path(xdg) / "dispex").string();
  const char* home = std::getenv("HOME");
  if (home != nullptr && *home != 0) {
    return (std::filesystem::path(home) / ".cache" / "dispex").string();
  }
  return {};
}

StatusOr<double> OffsetBound(const ExtractOptions& options, double base_diagonal) {
  if (options.search_distance.kind == SearchDistanceSpec::Kind::kAuto) return 0.0;
  return ResolveSearchDistance(options.search_distance, base_diagonal);
}

Status ChooseMethod(const ExtractOptions& options, ExtractInputs& inputs, ExtractReport& report) {
  report.method.used = ExtractMethod::kRays;
  if (options.method == ExtractMethod::kRays) return Status::Ok();
  const bool interpolate = options.method != ExtractMethod::kMapping;
  Stopwatch clock;
  MatchOptions match;
  match.threads = report.settings.threads;
  match.face_tables = false;  // the mapping reads the cells
  match.vertex_homes = false;
  if (interpolate) {  // the bound vector maps take too
    DISPEX_ASSIGN_OR_RETURN(match.max_offset, OffsetBound(options, report.inputs.base_diagonal));
  }
  StatusOr<SculptCorrespondence> correspondence = MatchSculpt(options, match, inputs, report);
  if (!correspondence.ok()) {
    report.times.match = clock.seconds();
    report.method.reason = correspondence.status().message();
    if (options.method != ExtractMethod::kAuto) {
      return Status::Error(
          fmt::format("method {}: {}", ExtractMethodName(options.method), report.method.reason));
    }
    return CancelRequested() ? Cancelled() : Status::Ok();
  }
  report.method.levels = correspondence->levels;
  report.method.max_offset = correspondence->max_offset;
  report.method.rms_offset = correspondence->rms_offset;
  DISPEX_ASSIGN_OR_RETURN(SculptMapping mapping, SculptMapping::Build(std::move(*correspondence),
                                                                      inputs.sculpt, inputs.faces));
  if (!interpolate) {  // what the rays through the cells need
    DISPEX_RETURN_IF_ERROR(mapping.MarkFolds(inputs.surface, inputs.sculpt, inputs.faces));
    mapping.BuildBlocks(inputs.sculpt);
  }
  inputs.mapping = std::make_unique<SculptMapping>(std::move(mapping));
  if (interpolate) inputs.grids = std::make_unique<MappingGrids>(*inputs.mapping);
  inputs.interpolate = interpolate;
  report.times.match = clock.seconds();
  report.method.used = interpolate ? ExtractMethod::kInterpolate : ExtractMethod::kMapping;
  return CancelRequested() ? Cancelled() : Status::Ok();
}

namespace {

// The quads of every block of cells (the mapping's SculptBlocks) whose box meets one of
// `boxes`, as a mesh (SculptPart). A quad's box lies in its block's, so this holds every quad
// whose box meets one of them; it reads only the blocks found, not every sculpt face.
Mesh SculptInBlocksMeeting(const ExtractInputs& inputs, std::span<const Box> boxes) {
  const SculptMapping& mapping = *inputs.mapping;
  const SculptBlocks& blocks = mapping.blocks();
  std::vector<std::uint8_t> keep(inputs.sculpt.num_faces(), 0);
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(blocks.num_blocks()), 0);
  for (const Box& query : boxes) {
    blocks.ForEachMeeting(query, [&](std::int64_t id) {
      if (std::exchange(seen[static_cast<std::size_t>(id)], 1)) return;
      const auto [face, bi, bj] = blocks.block(id);
      const int b = blocks.block_size(face);
      for (int j = bj * b; j < (bj + 1) * b; ++j) {
        for (int i = bi * b; i < (bi + 1) * b; ++i) {
          keep[static_cast<std::size_t>(SculptMapping::FaceOf(mapping.cell(face, i, j)))] = 1;
        }
      }
    });
  }
  return SculptPart(inputs.sculpt, keep);
}

// The sculpt the normal queries from `origins` along +- `directions`, `distance` long, can
// reach: each segment cut into pieces about a grid cell of the blocks long (a long segment's
// one box would cover most of the grid), each piece's box grown by 2^-16 of the coordinates'
// magnitude and of the distance (well beyond the margin Embree's window gets,
// trace/batch_kernels.h).
Mesh SculptNearSegments(const ExtractInputs& inputs, std::span<const Float3> origins,
                        std::span<const Float3> directions, float distance) {
  const double cell = inputs.mapping->blocks().cell_size();
  std::vector<Box> boxes;
  for (std::size_t k = 0; k < origins.size(); ++k) {
    const double o[3] = {origins[k].x, origins[k].y, origins[k].z};
    const double d[3] = {directions[k].x, directions[k].y, directions[k].z};
    const double length =
        2.0 * distance * std::max({std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])});
    const int pieces = static_cast<int>(std::clamp(std::ceil(length / cell), 1.0, 4096.0));
    double margin[3];
    for (int a = 0; a < 3; ++a) {
      margin[a] = (std::fabs(o[a]) + distance + inputs.tracer_options.scale) * 0x1p-16;
    }
    for (int p = 0; p < pieces; ++p) {
      const double t0 = distance * (2.0 * p / pieces - 1),
                   t1 = distance * (2.0 * (p + 1) / pieces - 1);
      Box& box = boxes.emplace_back();
      for (int a = 0; a < 3; ++a) {
        box.lower[a] = static_cast<float>(o[a] + std::min(t0 * d[a], t1 * d[a]) - margin[a]);
        box.upper[a] = static_cast<float>(o[a] + std::max(t0 * d[a], t1 * d[a]) + margin[a]);
      }
    }
  }
  return SculptInBlocksMeeting(inputs, boxes);
}

// SculptWithinReach through the blocks: the quads of every block whose box meets the reach
// box of a flagged face.
Mesh SculptNearFaces(const ExtractInputs& inputs, std::span<const std::uint8_t> flagged) {
  std::vector<Box> boxes;
  for (std::size_t f = 0; f < flagged.size(); ++f) {
    if (!flagged[f] || inputs.surface.is_hole(PtexFaceId(static_cast<int>(f)))) continue;
    boxes.push_back(inputs.face_keys->reach_boxes[f]);
  }
  return SculptInBlocksMeeting(inputs, boxes);
}

}  // namespace

StatusOr<SearchDistanceEstimate> EstimateSearchDistanceMapped(const ExtractInputs& inputs,
                                                              const CoarseSampling& coarse,
                                                              double base_diagonal) {
  constexpr int g = CoarseSampling::kGrid;
  constexpr std::int64_t per_face = g * g;
  const SearchDistanceOptions options;
  // Verified as EstimateSearchDistance's (LowerNearestHits).
  const NormalQuery query{static_cast<float>(options.ray_fraction * base_diagonal),
                          HitPolicy::kNearest, /*verify_hits=*/true};
  // The points of each face, which follow one another.
  std::vector<std::size_t> starts;
  for (std::size_t k = 0; k < coarse.ids.size(); ++k) {
    if (k == 0 || coarse.ids[k] / per_face != coarse.ids[k - 1] / per_face) starts.push_back(k);
  }
  starts.push_back(coarse.ids.size());
  std::vector<double> abs_t(coarse.ids.size(), -1.0);  // -1: a miss or not decided
  std::vector<std::uint8_t> decided(coarse.ids.size(), 0);
  struct Scratch {
    MappingScratch mapping;
    MappingCounters counters;
  };
  tbb::enumerable_thread_specific<Scratch> scratches;
  tbb::parallel_for(std::size_t{0}, starts.size() - 1, [&](std::size_t group) {
    Scratch& w = scratches.local();
    const std::size_t begin = starts[group], end = starts[group + 1];
    const auto face = static_cast<int>(coarse.ids[begin] / per_face);
    // The face's grid holds the coarse points (evaluated by SampleCoarsely) at their places;
    // TraceMapped reads only the samples listed.
    Float3 positions[per_face], normals[per_face];
    float t[per_face];
    std::uint8_t flags[per_face], undecided[per_face];
    std::int32_t samples[per_face];
    for (std::size_t k = begin; k < end; ++k) {
      const auto i = static_cast<std::int32_t>(coarse.ids[k] % per_face);
      samples[k - begin] = i;
      positions[i] = coarse.points[k];
      normals[i] = coarse.normals[k];
    }
    TraceMapped(*inputs.mapping, inputs.sculpt, PtexFaceId(face), g,
                std::span(samples, end - begin), positions, normals, query,
                NormalHits{t, {}, flags}, undecided, w.mapping, w.counters);
    for (std::size_t k = begin; k < end; ++k) {
      const auto i = static_cast<std::size_t>(samples[k - begin]);
      decided[k] = !undecided[i];
      if (decided[k] && (flags[i] & HitFlags::kHit)) abs_t[k] = std::fabs(double(t[i]));
    }
  });
  // The samples the mapping left undecided (near folds, or where another sheet may be nearer)
  // go to a BVH of the sculpt their rays can reach, as the ray path answers every sample.
  std::vector<std::size_t> rest;
  for (std::size_t k = 0; k < decided.size(); ++k) {
    if (!decided[k]) rest.push_back(k);
  }
  if (!rest.empty()) {
    std::vector<Float3> origins, directions;
    for (std::size_t k : rest) {
      origins.push_back(coarse.points[k]);
      directions.push_back(coarse.normals[k]);
    }
    const Mesh part = SculptNearSegments(inputs, origins, directions, query.distance);
    DISPEX_ASSIGN_OR_RETURN(
        std::unique_ptr<Tracer> tracer,
        MakeEmbreeTracer(part.num_faces() > 0 ? part : inputs.sculpt, inputs.tracer_options));
    std::vector<float> t(rest.size());
    std::vector<std::uint8_t> flags(rest.size());
    TraceCounters counters;
    tracer->TraceNormals(origins, directions, query, NormalHits{t, {}, flags}, counters);
    DISPEX_RETURN_IF_ERROR(tracer->status());
    for (std::size_t r = 0; r < rest.size(); ++r) {
      if (flags[r] & HitFlags::kHit) abs_t[rest[r]] = std::fabs(double(t[r]));
    }
  }
  std::vector<double> hits;
  for (double a : abs_t) {
    if (a >= 0) hits.push_back(a);
  }
  return SearchDistanceFromHits(std::move(hits), abs_t.size(), base_diagonal, options);
}

Status TraceFallback(ExtractInputs& inputs, std::span<const int> faces) {
  if (inputs.tracer) {
    if (inputs.traced.empty()) return Status::Ok();
    if (std::all_of(faces.begin(), faces.end(),
                    [&](int f) { return inputs.traced[static_cast<std::size_t>(f)] != 0; })) {
      return Status::Ok();
    }
  }
  Stopwatch clock;
  const auto n = static_cast<std::size_t>(inputs.surface.num_ptex_faces());
  std::vector<std::uint8_t> traced = inputs.tracer ? inputs.traced : std::vector<std::uint8_t>(n);
  for (int f : faces) traced[static_cast<std::size_t>(f)] = 1;
  const auto count = static_cast<std::size_t>(std::count(traced.begin(), traced.end(), 1));
  inputs.tracer.reset();
  inputs.traced_part = Mesh{};
  if (inputs.face_keys != nullptr && 2 * count <= n) {
    inputs.traced_part = inputs.mapping->blocks().empty()
                             ? SculptWithinReach(inputs, *inputs.face_keys, traced)
                             : SculptNearFaces(inputs, traced);
  }
  if (inputs.traced_part.num_faces() == 0) {
    inputs.traced.clear();
    DISPEX_ASSIGN_OR_RETURN(inputs.tracer, MakeEmbreeTracer(inputs.sculpt, inputs.tracer_options));
  } else {
    inputs.traced = std::move(traced);
    DISPEX_ASSIGN_OR_RETURN(inputs.tracer,
                            MakeEmbreeTracer(inputs.traced_part, inputs.tracer_options));
  }
  inputs.fallback_bvh_seconds += clock.seconds();
  return CancelRequested() ? Cancelled() : Status::Ok();
}

void ReportMapping(const ExtractInputs& inputs, const ProcessedFaces& faces,
                   ExtractReport& report) {
  report.method.fallback_samples = faces.fallback_samples;
  report.method.fallback_faces = faces.fallback_faces;
  report.times.bvh += inputs.fallback_bvh_seconds;
  if (inputs.interpolate) {
    report.tracer = fmt::format(
        "none: the sculpt's vertex displacements interpolated through the subdivision "
        "correspondence (level {})",
        report.method.levels);
    return;
  }
  report.tracer = fmt::format("subdivision correspondence (level {}; {})", report.method.levels,
                              PairedBlocksByDefault() ? "cells traced two at a time, AVX2"
                                                      : "cells traced one at a time, SSE2");
  if (!inputs.tracer) return;
  report.tracer +=
      fmt::format("; {} for {} samples of {} faces it left undecided",
                  inputs.tracer->stats().backend, faces.fallback_samples, faces.fallback_faces);
  if (!inputs.traced.empty()) {
    report.tracer += fmt::format(", {} of {} sculpt faces", inputs.traced_part.num_faces(),
                                 inputs.sculpt.num_faces());
  }
}

}  // namespace dispex::extract
