// Mesh reading throughput and peak memory on a sculpt-sized OBJ (v/f only, quads), or on given
// files (OBJ or PLY: the same sculpt in both formats compares the readers).
//
//   mesh_read_bench [--cache-dir DIR] [--grid N] [--threads 1,2] [--repeat 3] [--file PATH...]
//
// The input (an N x N vertex grid, (N-1)^2 quads, ~1.1 GB for the default N = 4000) is written
// once into the cache directory ($XDG_CACHE_HOME/dispex, else ~/.cache/dispex) and reused. Each
// measurement runs in a fresh child process, so its peak resident size (VmHWM) is its own; the
// file is read once beforehand so that every run finds it in the page cache. Reported: seconds,
// MB/s (file bytes / seconds), CPU seconds (user + system, all threads) and MB per CPU second
// (the rate the parser reaches when it has the cores to itself; wall time on a shared machine
// also counts other processes), peak RSS, and peak RSS over the bytes of the final arrays; then
// (median run) the time of ValidateMesh and of ComputeBounds + MedianEdgeLength on the result.
#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_output.h"
#include "core/mapped_file.h"
#include "core/system.h"
#include "dispex/mesh.h"

namespace {

std::string DefaultCacheDir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return std::string(xdg) + "/dispex";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.cache/dispex";
  return (std::filesystem::temp_directory_path() / "dispex-cache").string();
}

// A wavy height field, written the way sculpting tools write OBJ (6 decimals).
dispex::Status WriteGrid(const std::string& path, int n) {
  DISPEX_ASSIGN_OR_RETURN(dispex::AtomicOutput out, dispex::AtomicOutput::Create(path));
  fmt::memory_buffer buffer;
  auto flush = [&](bool force) -> dispex::Status {
    if (!force && buffer.size() < (8u << 20)) return dispex::Status::Ok();
    DISPEX_RETURN_IF_ERROR(out.Write(buffer.data(), buffer.size()));
    buffer.clear();
    return dispex::Status::Ok();
  };
  fmt::format_to(std::back_inserter(buffer), "# dispex benchmark grid {0}x{0}\n", n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double x = (i - n / 2) * 0.001, y = (j - n / 2) * 0.001;
      const double z =
          0.05 * std::sin(17.0 * x) * std::cos(13.0 * y) + 1e-4 * ((i * 7919 + j * 104729) % 97);
      fmt::format_to(std::back_inserter(buffer), "v {:.6f} {:.6f} {:.6f}\n", x, y, z);
    }
    DISPEX_RETURN_IF_ERROR(flush(false));
  }
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const long a = static_cast<long>(j) * n + i + 1;
      fmt::format_to(std::back_inserter(buffer), "f {} {} {} {}\n", a, a + 1, a + n + 1, a + n);
    }
    DISPEX_RETURN_IF_ERROR(flush(false));
  }
  DISPEX_RETURN_IF_ERROR(flush(true));
  return out.Commit();
}

struct Result {
  double seconds = 0;
  double cpu_seconds = 0;  // user + system time of the read
  double peak_rss = 0;
  double array_bytes = 0;
  double validate_seconds = 0;  // ValidateMesh
  double measure_seconds = 0;   // ComputeBounds + MedianEdgeLength
  std::size_t vertices = 0, faces = 0;
  int ok = 0;
};

// Runs one ReadMesh in a child process and returns what it measured.
Result MeasureInChild(const std::string& path, int threads) {
  int fds[2];
  if (::pipe(fds) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    Result r;
    dispex::Stopwatch watch;
    dispex::ReadOptions options;
    options.threads = threads;
    dispex::StatusOr<dispex::Mesh> mesh = dispex::ReadMesh(path, options);
    r.seconds = watch.seconds();
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    r.cpu_seconds = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                    1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    r.peak_rss = static_cast<double>(dispex::PeakResidentBytes());
    if (mesh.ok()) {
      r.ok = 1;
      r.vertices = mesh->num_vertices();
      r.faces = mesh->num_faces();
      r.array_bytes = static_cast<double>(mesh->positions.capacity() * sizeof(dispex::Float3) +
                                          mesh->face_offsets.capacity() * 4 +
                                          mesh->face_indices.capacity() * 4);
      // After the read's peak was taken: the summary `dispex info` computes.
      dispex::Stopwatch validate;
      const dispex::MeshValidation validation = dispex::ValidateMesh(*mesh);
      r.validate_seconds = validate.seconds();
      dispex::Stopwatch measure;
      const float diagonal = dispex::ComputeBounds(*mesh).diagonal();
      const double median = dispex::MedianEdgeLength(*mesh);
      r.measure_seconds = measure.seconds();
      if (!(diagonal > 0) || !(median > 0)) r.ok = 0;
    } else {
      std::fprintf(stderr, "mesh_read_bench: %s\n", mesh.status().message().c_str());
    }
    if (::write(fds[1], &r, sizeof r) != static_cast<ssize_t>(sizeof r)) _exit(2);
    _exit(0);
  }
  ::close(fds[1]);
  Result r;
  if (::read(fds[0], &r, sizeof r) != static_cast<ssize_t>(sizeof r)) r = {};
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return r;
}

// The table of one file: every thread count, `repeat` runs each. False when a run failed.
bool Measure(const std::string& path, const std::vector<int>& threads, int repeat) {
  const double bytes = static_cast<double>(std::filesystem::file_size(path));
  {
    // Bring the file into the page cache: the runs measure parsing, not the disk.
    dispex::StatusOr<dispex::MappedFile> file = dispex::MappedFile::Open(path);
    if (!file.ok()) return false;
    volatile unsigned char sum = 0;
    for (std::size_t i = 0; i < file->size(); i += 4096)
      sum = sum + static_cast<unsigned char>(file->data()[i]);
  }
  bool first = true;
  for (int t : threads) {
    std::vector<Result> runs;
    for (int i = 0; i < repeat; ++i) {
      Result r = MeasureInChild(path, t);
      if (!r.ok) return false;
      runs.push_back(r);
    }
    if (first) {
      fmt::print("file {} ({:.1f} MB), {} vertices, {} faces; {} cores\n", path, bytes / 1e6,
                 runs[0].vertices, runs[0].faces, std::max(1L, ::sysconf(_SC_NPROCESSORS_ONLN)));
      fmt::print("{:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>11} {:>9} {:>10} {:>10} {:>10}\n",
                 "threads", "best s", "median s", "best MB/s", "CPU s", "MB/CPU-s", "peak RSS MB",
                 "arrays MB", "RSS/arrays", "validate s", "bnd+med s");
      first = false;
    }
    std::sort(runs.begin(), runs.end(),
              [](const Result& a, const Result& b) { return a.seconds < b.seconds; });
    const Result& best = runs.front();
    const Result& median = runs[runs.size() / 2];
    double peak = 0;
    for (const Result& r : runs) peak = std::max(peak, r.peak_rss);
    fmt::print(
        "{:>7} {:>9.3f} {:>9.3f} {:>9.0f} {:>9.3f} {:>9.0f} {:>11.0f} {:>9.0f} {:>10.2f} {:>10.3f} "
        "{:>10.3f}\n",
        t, best.seconds, median.seconds, bytes / 1e6 / best.seconds, best.cpu_seconds,
        bytes / 1e6 / best.cpu_seconds, peak / 1e6, best.array_bytes / 1e6, peak / best.array_bytes,
        median.validate_seconds, median.measure_seconds);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Mesh reading throughput and peak memory on a generated quad OBJ or given files"};
  std::string cache_dir = DefaultCacheDir();
  int grid = 4000;
  std::vector<int> threads = {1, 2};
  int repeat = 3;
  app.add_option("--cache-dir", cache_dir, "where the generated OBJ is kept");
  app.add_option("--grid", grid, "vertices per side of the grid (4000: ~1.1 GB)")
      ->check(CLI::Range(2, 46000));
  app.add_option("--threads", threads, "thread counts to measure")->delimiter(',');
  app.add_option("--repeat", repeat, "runs per thread count (the best and median are shown)");
  std::vector<std::string> files;
  app.add_option("--file", files, "measure these meshes (OBJ or PLY) instead of the grid")
      ->check(CLI::ExistingFile);
  CLI11_PARSE(app, argc, argv);

  std::vector<std::string> paths = files;
  if (paths.empty()) {
    std::filesystem::create_directories(cache_dir);
    paths.push_back(fmt::format("{}/quad_grid_{}.obj", cache_dir, grid));
    if (!std::filesystem::exists(paths[0])) {
      std::fprintf(stderr, "writing %s ...\n", paths[0].c_str());
      dispex::Status written = WriteGrid(paths[0], grid);
      if (!written.ok()) {
        std::fprintf(stderr, "mesh_read_bench: %s\n", written.message().c_str());
        return 1;
      }
    }
  }
  for (const std::string& path : paths) {
    if (!Measure(path, threads, repeat)) return 1;
  }
  return 0;
}
