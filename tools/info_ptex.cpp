// TEMPORARY during development: replaced by the ptex module's summary.
#include "command.h"
#include "info.h"
namespace dispex::cli {
int PtexInfo(const InfoOptions& options) {
  return ReportFailure(Status::Error(options.path + ": ptex summary not built yet"));
}
}  // namespace dispex::cli
