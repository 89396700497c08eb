// TEMPORARY during development: replaced by the mesh module's summary.
#include "command.h"
#include "info.h"
namespace dispex::cli {
int MeshInfo(const InfoOptions& options) {
  return ReportFailure(Status::Error(options.path + ": mesh summary not built yet"));
}
}  // namespace dispex::cli
