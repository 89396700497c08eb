// ptex_write_bench: writes a generated float displacement map of about N texels (default
// 30M: smooth random faces of mixed, partly non-square resolutions, a few constant faces)
// with each compressor / level asked for, on T threads (default 2), and reports: the time to
// submit every face (SetFace: conversion, reductions, compression) and its input MB/s, the
// time of Finish() (assembly, write, fsync, rename), the total input MB/s, the file size and
// its ratio to the float32 input (reductions add a third), the compressed bytes the writer
// held before Finish; then reads the file back (open + inflate every block at every level).
// CPU seconds (all threads) are printed beside wall seconds, and "MB/cpu s" is the input
// written per CPU second, which is what a shared machine's load does not change.
//
//   ptex_write_bench [--texels N] [--threads T] [--dir DIR] [--configs libdeflate:1,zlib:6,...]
//
// Face textures come from a small pool generated up front (each face's data is independent,
// and every face is its own zlib stream, so reuse does not help the compressor); the timed
// part is only PtexWriter::SetFace over all faces (TBB parallel_for) plus Finish().
#include <sys/resource.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "dispex/ptex.h"

namespace {

using Clock = std::chrono::steady_clock;

// CPU seconds used by the process so far (all threads, user + system): on a shared machine
// this is the figure that does not depend on what else runs.
double CpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct Config {
  dispex::PtexCompressor compressor;
  int level;
  std::string name;
};

struct Face {
  dispex::PtexFaceInfo info;
  int pattern = -1;  // index into the pool of its resolution, -1: constant
};

// Smooth displacement-like values: a few random low-frequency waves plus fine noise, so the
// low mantissa bits are as incompressible as measured displacements are.
std::vector<float> SmoothFace(int ures, int vres, std::mt19937& rng) {
  std::uniform_real_distribution<float> uni(0, 1);
  float amp[3], fu[3], fv[3], ph[3];
  for (int k = 0; k < 3; ++k) {
    amp[k] = 0.02f * uni(rng) / float(k + 1);
    fu[k] = 6.28f * (1 + 3 * uni(rng)) * float(k + 1);
    fv[k] = 6.28f * (1 + 3 * uni(rng)) * float(k + 1);
    ph[k] = 6.28f * uni(rng);
  }
  std::normal_distribution<float> noise(0, 1e-5f);
  std::vector<float> t(std::size_t(ures) * vres);
  for (int v = 0; v < vres; ++v) {
    for (int u = 0; u < ures; ++u) {
      const float x = (u + 0.5f) / ures, y = (v + 0.5f) / vres;
      float d = 0;
      for (int k = 0; k < 3; ++k) d += amp[k] * std::sin(fu[k] * x + ph[k]) * std::cos(fv[k] * y);
      t[std::size_t(v) * ures + u] = d + noise(rng);
    }
  }
  return t;
}

std::vector<Config> ParseConfigs(const std::string& list) {
  std::vector<Config> configs;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto colon = item.find(':');
    const std::string name = item.substr(0, colon);
    const int level = colon == std::string::npos ? -1 : std::atoi(item.c_str() + colon + 1);
    if (name == "libdeflate") {
      configs.push_back({dispex::PtexCompressor::kLibdeflate, level, item});
    } else if (name == "zlib") {
      configs.push_back({dispex::PtexCompressor::kZlib, level, item});
    } else {
      std::fprintf(stderr, "unknown compressor %s\n", name.c_str());
      std::exit(2);
    }
  }
  return configs;
}

}  // namespace

int main(int argc, char** argv) {
  long long target = 30'000'000;
  int threads = 2;
  std::string dir = std::filesystem::temp_directory_path().string();
  std::string configs_arg = "libdeflate:1,libdeflate:6,zlib:1,zlib:6";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--texels")
      target = std::atoll(argv[i + 1]);
    else if (a == "--threads")
      threads = std::atoi(argv[i + 1]);
    else if (a == "--dir")
      dir = argv[i + 1];
    else if (a == "--configs")
      configs_arg = argv[i + 1];
    else {
      std::fprintf(stderr, "usage: %s [--texels N] [--threads T] [--dir DIR] [--configs ...]\n",
                   argv[0]);
      return 2;
    }
  }
  const std::vector<Config> configs = ParseConfigs(configs_arg);

  // Faces: resolutions 16..512 per side, u and v independent within a factor 4; 3% constant.
  std::mt19937 rng(2024);
  const int kPool = 8;
  std::vector<std::vector<std::vector<float>>> pool(10 * 10);
  std::vector<Face> faces;
  long long texels = 0;
  std::uniform_int_distribution<int> lg(4, 8), skew(-2, 2);
  while (texels < target) {
    Face f;
    f.info.ulog2 = static_cast<std::int8_t>(lg(rng));
    f.info.vlog2 = static_cast<std::int8_t>(std::clamp(f.info.ulog2 + skew(rng), 4, 9));
    if (rng() % 33 == 0) {
      f.pattern = -1;
    } else {
      auto& p = pool[std::size_t(f.info.ulog2 * 10 + f.info.vlog2)];
      if (p.size() < kPool) p.push_back(SmoothFace(f.info.ures(), f.info.vres(), rng));
      f.pattern = static_cast<int>(rng() % p.size());
    }
    texels += static_cast<long long>(f.info.num_texels());
    faces.push_back(f);
  }
  for (std::size_t i = 0; i < faces.size(); ++i) {  // a ring of neighbours: realistic records
    faces[i].info.adjfaces[1] = static_cast<std::int32_t>((i + 1) % faces.size());
    faces[i].info.adjedges[1] = 3;
    faces[i].info.adjfaces[3] = static_cast<std::int32_t>((i + faces.size() - 1) % faces.size());
    faces[i].info.adjedges[3] = 1;
  }
  const double input_mb = double(texels) * 4 / 1e6;
  std::printf("map: %zu faces, %lld texels (%.1f MB of float32), %d threads\n", faces.size(),
              texels, input_mb, threads);
  std::printf("%-13s %8s %10s %8s %8s %10s %9s %8s %6s %8s %8s %9s %8s\n", "config", "faces s",
              "faces MB/s", "cpu s", "finish s", "total MB/s", "MB/cpu s", "file MB", "ratio",
              "held MB", "read s", "read MB/s", "cpu s");

  tbb::task_arena arena(threads);
  for (const Config& c : configs) {
    const std::string path = dir + "/ptex_write_bench.ptx";
    dispex::PtexWriterOptions options;
    options.compressor = c.compressor;
    options.compression_level = c.level;
    const auto t0 = Clock::now();
    const double cpu0 = CpuSeconds();
    auto writer = dispex::PtexWriter::Create(path, options, static_cast<int>(faces.size()));
    if (!writer.ok()) {
      std::fprintf(stderr, "%s\n", writer.status().message().c_str());
      return 1;
    }
    std::atomic<bool> failed{false};
    arena.execute([&] {
      tbb::parallel_for(std::size_t{0}, faces.size(), [&](std::size_t i) {
        const Face& f = faces[i];
        const dispex::PtexFaceId id(static_cast<int>(i));
        dispex::Status s =
            f.pattern < 0
                ? writer->SetConstantFace(id, f.info, std::vector<float>{0.0f})
                : writer->SetFace(
                      id, f.info,
                      pool[std::size_t(f.info.ulog2 * 10 + f.info.vlog2)][std::size_t(f.pattern)]);
        if (!s.ok()) failed = true;
      });
    });
    const std::size_t held = writer->compressed_bytes();
    const double set_s = std::chrono::duration<double>(Clock::now() - t0).count();
    const double set_cpu = CpuSeconds() - cpu0;
    dispex::Status s = writer->Finish();
    const double write_s = std::chrono::duration<double>(Clock::now() - t0).count();
    const double write_cpu = CpuSeconds() - cpu0;
    if (failed || !s.ok()) {
      std::fprintf(stderr, "write failed: %s\n", s.message().c_str());
      return 1;
    }
    const double file_mb = double(std::filesystem::file_size(path)) / 1e6;
    const auto r0 = Clock::now();
    const double rcpu0 = CpuSeconds();
    auto file = dispex::PtexFile::Open(path);
    dispex::Status valid = file.ok() ? file->Validate() : file.status();
    const double read_s = std::chrono::duration<double>(Clock::now() - r0).count();
    const double read_cpu = CpuSeconds() - rcpu0;
    if (!valid.ok()) {
      std::fprintf(stderr, "read failed: %s\n", valid.message().c_str());
      return 1;
    }
    std::printf("%-13s %8.3f %10.1f %8.3f %8.3f %10.1f %9.1f %8.2f %6.3f %8.1f %8.3f %9.1f %8.3f\n",
                c.name.c_str(), set_s, input_mb / set_s, set_cpu, write_s - set_s,
                input_mb / write_s, input_mb / write_cpu, file_mb, file_mb / input_mb,
                double(held) / 1e6, read_s, input_mb / read_s, read_cpu);
    std::filesystem::remove(path);
  }
  return 0;
}
