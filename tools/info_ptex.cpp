// `dispex info FILE.ptx`: the Ptex part of the info subcommand (see cmd_info.cpp).
//
// Without flags: a summary (after checking every block of the file). --faces: one line per
// face instead. --dump FACE: the level-0 texels of one face. --json: the summary as JSON
// (with --faces, a "faces" array too).
#include <fmt/format.h>

#include <cstdio>
#include <string>
#include <vector>

#include "command.h"
#include "dispex/ptex.h"
#include "dispex/ptex_describe.h"
#include "info.h"

namespace dispex::cli {

int PtexInfo(const InfoOptions& options) {
  if (options.dump_face < -1) {
    return ReportFailure(Status::Error(options.path + ": --dump face id " +
                                       std::to_string(options.dump_face) + " is negative"));
  }
  StatusOr<PtexFile> opened = PtexFile::Open(options.path);
  if (!opened.ok()) return ReportFailure(opened.status());
  const PtexFile& file = *opened;
  // Every block is inflated and checked before anything is reported.
  if (Status valid = file.Validate(); !valid.ok()) return ReportFailure(valid);

  if (options.json) {
    std::fputs(PtexSummaryJson(file, options.faces).c_str(), stdout);
    std::fputc('\n', stdout);
    return 0;
  }
  std::string out;
  if (options.faces) {
    if (Status s = FormatPtexFaces(file, out); !s.ok()) return ReportFailure(s);
  }
  if (options.dump_face >= 0) {
    if (Status s = FormatPtexTexels(file, PtexFaceId(options.dump_face), out); !s.ok()) {
      return ReportFailure(s);
    }
  }
  if (!options.faces && options.dump_face < 0) out = FormatPtexSummary(file);
  std::fputs(out.c_str(), stdout);
  return 0;
}

}  // namespace dispex::cli
