// consumer CAGE WORKDIR: a sculpt made from CAGE, a map extracted from it, read back. Checks
// that the headers' version is the library's and that the map records it. Exit 0 when all
// holds; one line on stderr otherwise.
#include <cstdio>
#include <string>

#include "dispex/dispex.h"  // the front door alone

namespace {
int Fail(const std::string& what) {
  std::fprintf(stderr, "consumer: %s\n", what.c_str());
  return 1;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) return Fail("usage: consumer CAGE WORKDIR");
  if (std::string(DISPEX_VERSION_STRING) != dispex::Version()) {
    return Fail(std::string("headers ") + DISPEX_VERSION_STRING + ", library " + dispex::Version());
  }
  const std::string dir = argv[2];
  dispex::MakeSculptOptions sculpt;
  sculpt.cage_path = argv[1];
  sculpt.output_path = dir + "/sculpt.obj";
  sculpt.levels = 2;
  auto made = dispex::MakeSculpt(sculpt);
  if (!made.ok()) return Fail(made.status().message());
  dispex::ExtractOptions options;
  options.base_path = argv[1];
  options.sculpt_path = sculpt.output_path;
  options.output_path = dir + "/map.ptx";
  auto report = dispex::Extract(options);
  if (!report.ok()) return Fail(report.status().message());
  auto map = dispex::PtexFile::Open(options.output_path);
  if (!map.ok()) return Fail(map.status().message());
  const dispex::PtexMetaItem* version = map->FindMetaData("dispex:version");
  if (version == nullptr || version->AsString() != dispex::Version()) {
    return Fail("the map does not record the library's version");
  }
  if (map->num_faces() != static_cast<int>(report->inputs.ptex_faces)) {
    return Fail("the map's faces are not the report's");
  }
  std::printf("dispex %s: %d faces\n", dispex::Version(), map->num_faces());
  return 0;
}
