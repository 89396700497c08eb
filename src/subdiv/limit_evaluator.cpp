// LimitEvaluator: argument checks around a FaceSampler, so that bad ids, holes and short
// buffers are Status errors and the sampler's loops can trust their inputs.
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <string_view>

#include "dispex/subdiv.h"
#include "subdiv/face_sampler.h"
#include "subdiv/surface_impl.h"

namespace dispex {

struct LimitEvaluator::Impl {
  using Frames = LimitEvaluator::Frames;
  explicit Impl(const LimitSurface::Impl& s) : surface(s), sampler(s) {}
  const LimitSurface::Impl& surface;
  subdiv::FaceSampler sampler;

  // Every output holds `needed` floats; derivatives come both or neither, with normals.
  // `what` says what needs them: "a 3x2 grid needs", "5 points need".
  Status CheckOutputs(PtexFaceId face, std::string_view what, std::size_t needed,
                      const Frames& out) const {
    const bool frames = !out.du.empty() || !out.dv.empty();
    if (out.positions.size() < needed || (!out.normals.empty() && out.normals.size() < needed) ||
        (frames && (out.normals.empty() || out.du.size() < needed || out.dv.size() < needed))) {
      return Status::Error(
          fmt::format("{}: Ptex face {}: {} {} floats per output (got {} positions, {} normals, "
                      "{} and {} derivatives; derivatives need normals)",
                      surface.source, face.value, what, needed, out.positions.size(),
                      out.normals.size(), out.du.size(), out.dv.size()));
    }
    return Status::Ok();
  }

  Status BindChecked(PtexFaceId face) {
    if (face.value < 0 || face.value >= surface.num_ptex_faces()) {
      return Status::Error(fmt::format("{}: Ptex face {} out of range ({} Ptex faces)",
                                       surface.source, face.value, surface.num_ptex_faces()));
    }
    switch (sampler.Bind(face.value)) {
      case subdiv::FaceSampler::BindResult::kOk:
        return Status::Ok();
      case subdiv::FaceSampler::BindResult::kNoSurface:
        return Status::Error(fmt::format("{}: Ptex face {} (base face {}) has no limit surface",
                                         surface.source, face.value,
                                         surface.ptex_base[face.value]));
      case subdiv::FaceSampler::BindResult::kFailed:
        break;
    }
    return Status::Error(
        fmt::format("{}: OpenSubdiv could not build the limit surface of base "
                    "face {}: {}",
                    surface.source, surface.ptex_base[face.value], sampler.error()));
  }
};

LimitEvaluator::LimitEvaluator(const LimitSurface& surface)
    : impl_(std::make_unique<Impl>(SurfaceImpl(surface))) {}
LimitEvaluator::LimitEvaluator(LimitEvaluator&&) noexcept = default;
LimitEvaluator& LimitEvaluator::operator=(LimitEvaluator&&) noexcept = default;
LimitEvaluator::~LimitEvaluator() = default;

Status LimitEvaluator::EvaluateGrid(PtexFaceId face, int rx, int ry, std::span<float> positions,
                                    std::span<float> normals) {
  return EvaluateGridFrames(face, rx, ry, {positions, normals, {}, {}});
}

Status LimitEvaluator::EvaluatePoints(PtexFaceId face, std::span<const float> uv,
                                      std::span<float> positions, std::span<float> normals) {
  return EvaluatePointFrames(face, uv, {positions, normals, {}, {}});
}

Status LimitEvaluator::EvaluateGridFrames(PtexFaceId face, int rx, int ry, Frames out) {
  const std::span<float> positions = out.positions, normals = out.normals;
  if (rx < 1 || ry < 1) {
    return Status::Error(fmt::format("{}: Ptex face {}: grid {}x{} is empty", impl_->surface.source,
                                     face.value, rx, ry));
  }
  const std::size_t needed = 3 * static_cast<std::size_t>(rx) * static_cast<std::size_t>(ry);
  DISPEX_RETURN_IF_ERROR(
      impl_->CheckOutputs(face, fmt::format("a {}x{} grid needs", rx, ry), needed, out));
  DISPEX_RETURN_IF_ERROR(impl_->BindChecked(face));
  impl_->sampler.Grid(rx, ry, positions.data(), normals.empty() ? nullptr : normals.data(),
                      out.du.empty() ? nullptr : out.du.data(),
                      out.dv.empty() ? nullptr : out.dv.data());
  return Status::Ok();
}

Status LimitEvaluator::EvaluatePointFrames(PtexFaceId face, std::span<const float> uv, Frames out) {
  if (uv.size() % 2 != 0) {
    return Status::Error(fmt::format("{}: Ptex face {}: {} uv values is not a list of pairs",
                                     impl_->surface.source, face.value, uv.size()));
  }
  const std::size_t n = uv.size() / 2;
  DISPEX_RETURN_IF_ERROR(impl_->CheckOutputs(face, fmt::format("{} points need", n), 3 * n, out));
  for (std::size_t i = 0; i < n; ++i) {
    const float u = uv[2 * i], v = uv[2 * i + 1];
    if (!(u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f)) {
      return Status::Error(
          fmt::format("{}: Ptex face {}: point {} (u,v) = ({}, {}) is outside "
                      "[0,1]^2",
                      impl_->surface.source, face.value, i, u, v));
    }
  }
  DISPEX_RETURN_IF_ERROR(impl_->BindChecked(face));
  const bool frames = !out.du.empty();
  for (std::size_t i = 0; i < n; ++i) {
    impl_->sampler.Point(uv[2 * i], uv[2 * i + 1], &out.positions[3 * i],
                         out.normals.empty() ? nullptr : &out.normals[3 * i],
                         frames ? &out.du[3 * i] : nullptr, frames ? &out.dv[3 * i] : nullptr);
  }
  return Status::Ok();
}

const LimitEvaluatorStats& LimitEvaluator::stats() const {
  return impl_->sampler.stats();
}

}  // namespace dispex
