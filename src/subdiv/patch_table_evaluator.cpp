// Follows OpenSubdiv's far_tutorial_5_x / regression/bfr_evaluate/farPatchEvaluator: refine
// adaptively, interpolate the refined points with Far::PrimvarRefiner, append the local
// (end-cap) points from the patch table's stencils, then PatchMap::FindPatch +
// PatchTable::EvaluateBasis per (u,v).
#include "subdiv/patch_table_evaluator.h"

#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <string>

#include "subdiv/osd_messages.h"

namespace dispex::subdiv {
namespace Far = OpenSubdiv::Far;

StatusOr<std::unique_ptr<PatchTableEvaluator>> PatchTableEvaluator::Build(
    const Far::TopologyRefiner& base, const std::vector<double>& positions,
    const std::vector<int>& base_faces, int isolation, int smooth) {
  OsdMessageCapture capture;
  std::unique_ptr<PatchTableEvaluator> e(new PatchTableEvaluator());
  e->refiner_.reset(Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Create(base));

  Far::PatchTableFactory::Options options(isolation);
  options.SetPatchPrecision<double>();
  options.useInfSharpPatch = true;
  options.generateLegacySharpCornerPatches = false;
  options.shareEndCapPatchPoints = false;
  options.endCapType = Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS;
  Far::TopologyRefiner::AdaptiveOptions adaptive = options.GetRefineAdaptiveOptions();
  adaptive.isolationLevel = isolation;
  adaptive.secondaryLevel = smooth;
  const Far::ConstIndexArray selected(base_faces.data(), static_cast<int>(base_faces.size()));
  e->refiner_->RefineAdaptive(adaptive, selected);
  e->table_.reset(Far::PatchTableFactory::Create(*e->refiner_, options, selected));
  if (!e->table_ || !capture.empty()) {
    return Status::Error("OpenSubdiv patch table failed: " +
                         (capture.empty() ? std::string("no table") : capture.messages()));
  }
  e->map_ = std::make_unique<Far::PatchMap>(*e->table_);

  const int num_base = e->refiner_->GetLevel(0).GetNumVertices();
  const int num_refined = e->refiner_->GetNumVerticesTotal() - num_base;
  const int num_local = e->table_->GetNumLocalPoints();
  e->points_.resize(static_cast<std::size_t>(num_base + num_refined + num_local));
  for (int v = 0; v < num_base; ++v) {
    for (int k = 0; k < 3; ++k) e->points_[v].p[k] = positions[3 * static_cast<std::size_t>(v) + k];
  }
  Point3* points = e->points_.data();
  Far::PrimvarRefinerReal<double> primvar(*e->refiner_);
  Point3* src = points;
  for (int level = 1; level < e->refiner_->GetNumLevels(); ++level) {
    Point3* dst = src + e->refiner_->GetLevel(level - 1).GetNumVertices();
    primvar.Interpolate(level, src, dst);
    src = dst;
  }
  if (num_local > 0) {
    e->table_->GetLocalPointStencilTable<double>()->UpdateValues(points,
                                                                 points + num_base + num_refined);
  }
  if (!capture.empty()) return Status::Error("OpenSubdiv patch points: " + capture.messages());
  return e;
}

bool PatchTableEvaluator::Evaluate(int ptex, double u, double v, double p[3], double du[3],
                                   double dv[3]) const {
  const Far::PatchTable::PatchHandle* handle = map_->FindPatch(ptex, u, v);
  if (handle == nullptr) return false;
  double w[20], wu[20], wv[20];
  table_->EvaluateBasis(*handle, u, v, w, wu, wv);
  const Far::ConstIndexArray cvs = table_->GetPatchVertices(*handle);
  for (int k = 0; k < 3; ++k) p[k] = du[k] = dv[k] = 0;
  for (int i = 0; i < cvs.size(); ++i) {
    const double* c = points_[cvs[i]].p;
    for (int k = 0; k < 3; ++k) {
      p[k] += w[i] * c[k];
      du[k] += wu[i] * c[k];
      dv[k] += wv[i] * c[k];
    }
  }
  return true;
}

}  // namespace dispex::subdiv
