// ExtractAsset: read each file once, split the meshes into shapes, pair them by name, and run
// one shape's extraction (ExtractShape) per pair, shapes in parallel.
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include "core/progress.h"
#include "dispex/cancel.h"
#include "dispex/extract.h"
#include "dispex/shapes.h"
#include "dispex/version.h"
#include "extract/extract_shape.h"
#include "extract/parallel_errors.h"

namespace dispex::extract {

namespace {

namespace fs = std::filesystem;

// One map to make.
struct ShapeJob {
  std::string name;
  ExtractOptions options;  // paths and output set
  Mesh base, sculpt;
};

// The files of the asset, each read once, in parallel.
StatusOr<std::map<std::string, Mesh>> ReadFiles(const std::vector<std::string>& paths,
                                                int threads) {
  std::vector<std::string> unique;
  for (const std::string& p : paths) {
    if (std::find(unique.begin(), unique.end(), p) == unique.end()) unique.push_back(p);
  }
  std::vector<std::optional<StatusOr<Mesh>>> read(unique.size());
  ReadOptions read_options;
  read_options.threads = threads;
  tbb::parallel_for(std::size_t{0}, unique.size(),
                    [&](std::size_t i) { read[i].emplace(ReadMesh(unique[i], read_options)); });
  std::map<std::string, Mesh> out;
  for (std::size_t i = 0; i < unique.size(); ++i) {
    if (!read[i]->ok()) return read[i]->status();
    out.emplace(unique[i], std::move(*read[i]).value());
  }
  return out;
}

// The shapes of each file, split once.
class ShapeSource {
 public:
  // `shared`: files read both as a base and as a sculpt, split twice from the same mesh.
  ShapeSource(std::map<std::string, Mesh> files, std::vector<std::string> shared)
      : files_(std::move(files)), shared_(std::move(shared)) {}

  StatusOr<std::vector<MeshShape>*> Shapes(const std::string& path, bool base) {
    auto& cache = base ? base_shapes_ : sculpt_shapes_;
    auto it = cache.find(path);
    if (it == cache.end()) {
      // A file that is only a base or only a sculpt gives its arrays to a single shape.
      const bool both = std::find(shared_.begin(), shared_.end(), path) != shared_.end();
      Mesh& mesh = files_.at(path);
      DISPEX_ASSIGN_OR_RETURN(std::vector<MeshShape> shapes,
                              both ? SplitShapes(static_cast<const Mesh&>(mesh), base)
                                   : SplitShapes(std::move(mesh), base));
      it = cache.emplace(path, std::move(shapes)).first;
    }
    return &it->second;
  }

 private:
  std::map<std::string, Mesh> files_;
  std::vector<std::string> shared_;
  std::map<std::string, std::vector<MeshShape>> base_shapes_, sculpt_shapes_;
};

StatusOr<std::vector<ShapeJob>> PlanFromFiles(const ExtractAssetOptions& o, ShapeSource& source,
                                              std::vector<std::string>& warnings) {
  const ExtractOptions& d = o.options;
  DISPEX_ASSIGN_OR_RETURN(std::vector<MeshShape> * base, source.Shapes(d.base_path, true));
  DISPEX_ASSIGN_OR_RETURN(std::vector<MeshShape> * sculpt, source.Shapes(d.sculpt_path, false));
  DISPEX_ASSIGN_OR_RETURN(ShapeMatch match,
                          MatchShapes(*base, *sculpt, o.shapes, d.base_path, d.sculpt_path));
  warnings.insert(warnings.end(), match.warnings.begin(), match.warnings.end());
  std::vector<ShapeJob> jobs;
  for (std::size_t i = 0; i < match.base_index.size(); ++i) {
    MeshShape& b = (*base)[match.base_index[i]];
    MeshShape& s = (*sculpt)[match.sculpt_index[i]];
    ShapeJob job{b.name, d, std::move(b.mesh), std::move(s.mesh)};
    job.options.output_path = (fs::path(o.output_dir) / (b.file_name + ".ptx")).string();
    jobs.push_back(std::move(job));
  }
  return jobs;
}

StatusOr<std::vector<ShapeJob>> PlanFromManifest(const ExtractAssetOptions& o,
                                                 ShapeSource& source) {
  std::vector<std::string> names;
  for (const AssetShapeSpec& spec : o.manifest) names.push_back(spec.name);
  const std::vector<std::string> files = ShapeFileNames(names);
  std::vector<ShapeJob> jobs;
  std::map<std::pair<std::string, std::size_t>, std::string> taken;  // shape -> entry
  for (std::size_t i = 0; i < o.manifest.size(); ++i) {
    const AssetShapeSpec& spec = o.manifest[i];
    DISPEX_ASSIGN_OR_RETURN(std::vector<MeshShape> * base, source.Shapes(spec.base_path, true));
    DISPEX_ASSIGN_OR_RETURN(std::vector<MeshShape> * sculpt,
                            source.Shapes(spec.sculpt_path, false));
    const std::string selected[] = {spec.name};
    // A single-shape file pairs whatever its name; a file of several is looked up by name.
    const std::span<const std::string> selection =
        base->size() == 1 ? std::span<const std::string>() : std::span(selected);
    DISPEX_ASSIGN_OR_RETURN(
        ShapeMatch match, MatchShapes(*base, *sculpt, selection, spec.base_path, spec.sculpt_path));
    // Each shape of a file serves one entry, which takes its arrays.
    for (const auto& [path, index] :
         {std::pair(spec.base_path, match.base_index[0]),
          std::pair("sculpt " + spec.sculpt_path, match.sculpt_index[0])}) {
      const auto [at, inserted] = taken.emplace(std::pair(path, index), spec.name);
      if (!inserted) {
        return Status::Error(fmt::format("shapes '{}' and '{}' use the same shape of {}",
                                         at->second, spec.name, path));
      }
    }
    ShapeJob job{spec.name, spec.options, std::move((*base)[match.base_index[0]].mesh),
                 std::move((*sculpt)[match.sculpt_index[0]].mesh)};
    job.options.base_path = spec.base_path;
    job.options.sculpt_path = spec.sculpt_path;
    job.options.output_path = (fs::path(o.output_dir) / (files[i] + ".ptx")).string();
    jobs.push_back(std::move(job));
  }
  return jobs;
}

StatusOr<AssetReport> ExtractAssetInArena(const ExtractAssetOptions& o, int threads) {
  Stopwatch total_clock;
  AssetReport report;
  report.version = Version();
  report.output_dir = o.output_dir;

  std::vector<std::string> bases, sculpts;
  if (o.manifest.empty()) {
    bases = {o.options.base_path};
    sculpts = {o.options.sculpt_path};
  } else {
    for (const AssetShapeSpec& spec : o.manifest) {
      bases.push_back(spec.base_path);
      sculpts.push_back(spec.sculpt_path);
    }
  }
  std::vector<std::string> paths = bases, shared;
  for (const std::string& p : sculpts) {
    paths.push_back(p);
    if (std::find(bases.begin(), bases.end(), p) != bases.end()) shared.push_back(p);
  }
  Stopwatch read_clock;
  DISPEX_ASSIGN_OR_RETURN(auto files, ReadFiles(paths, o.options.threads));
  report.t_read = read_clock.seconds();
  if (CancelRequested()) return Cancelled();
  ShapeSource source(std::move(files), std::move(shared));
  DISPEX_ASSIGN_OR_RETURN(
      std::vector<ShapeJob> jobs,
      o.manifest.empty() ? PlanFromFiles(o, source, report.warnings) : PlanFromManifest(o, source));
  std::error_code ec;
  fs::create_directories(o.output_dir, ec);
  if (ec) {
    return Status::Error(
        fmt::format("{}: cannot create the output folder: {}", o.output_dir, ec.message()));
  }

  report.shapes.resize(jobs.size());
  // A program's counter (ExtractOptions::progress_counter) counts the shapes done.
  Progress bar("extract", jobs.size(), "shapes", o.options.progress, o.options.progress_counter);
  FirstError error;
  tbb::parallel_for(std::size_t{0}, jobs.size(), [&](std::size_t i) {
    if (error.failed()) return;
    ShapeJob& job = jobs[i];
    job.options.progress = false;
    job.options.progress_counter = nullptr;
    Stopwatch clock;
    ExtractReport shape_report = StartReport(job.options, threads);
    shape_report.shape = job.name;
    const std::uint64_t memory_limit = MemoryLimit(job.options);
    auto inputs = InputsFromMeshes(job.options, std::move(job.base), std::move(job.sculpt),
                                   memory_limit, shape_report);
    auto done = inputs.ok()
                    ? ExtractShape(job.options, std::move(*inputs), std::move(shape_report), clock)
                    : StatusOr<ExtractReport>(inputs.status());
    if (!done.ok()) {
      return error.Record(static_cast<int>(i),
                          done.status().WithPrefix(fmt::format("shape '{}'", job.name)));
    }
    report.shapes[i] = {job.name, job.options.output_path, std::move(*done)};
    bar.Advance();
  });
  bar.Finish();
  if (error.failed()) return error.status();
  report.peak_rss_bytes = PeakResidentBytes();
  report.t_total = total_clock.seconds();
  return report;
}

Status ValidateAssetOptions(const ExtractAssetOptions& o) {
  if (o.output_dir.empty()) return Status::Error("no output folder given (output_dir)");
  if (o.options.shard_count > 0) {
    return Status::Error(
        "shard_count: assets of several shapes are not made in shards; shard each shape's "
        "files as a map of its own (docs/FARM.md)");
  }
  if (!o.manifest.empty() && !o.shapes.empty()) {
    return Status::Error("shapes selects shapes of base_path; a manifest names its own");
  }
  auto check = [&](ExtractOptions options, const std::string& base, const std::string& sculpt) {
    options.base_path = base;
    options.sculpt_path = sculpt;
    options.output_path = (fs::path(o.output_dir) / "shape.ptx").string();
    return ValidateExtractOptions(options);
  };
  if (o.manifest.empty()) return check(o.options, o.options.base_path, o.options.sculpt_path);
  for (const AssetShapeSpec& spec : o.manifest) {
    Status s = check(spec.options, spec.base_path, spec.sculpt_path);
    if (!s.ok()) return s.WithPrefix(fmt::format("shape '{}'", spec.name));
  }
  return Status::Ok();
}

}  // namespace

}  // namespace dispex::extract

namespace dispex {

StatusOr<AssetReport> ExtractAsset(const ExtractAssetOptions& options) {
  DISPEX_RETURN_IF_ERROR(extract::ValidateAssetOptions(options));
  return extract::RunInArena(options.options.threads, [&](int threads) {
    return extract::ExtractAssetInArena(options, threads);
  });
}

}  // namespace dispex
