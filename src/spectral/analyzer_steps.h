// SpectralAnalyzer's DCT steps one at a time, for the spectral tests: the forward and inverse
// transforms and the DCT-domain resampling Analyze is built from (declared private in
// dispex/spectral.h, implemented in spectral_analyzer.cpp). Same size rules and errors as
// SpectralAnalyzer::Analyze.
#pragma once

#include <span>

#include "dispex/spectral.h"
#include "dispex/status.h"

namespace dispex::spectral {

struct AnalyzerSteps {
  // Orthonormal 2-D DCT-II of an nx x ny block: coefficients[v * nx + u] = F(u,v).
  static Status ForwardDct(SpectralAnalyzer& analyzer, std::span<const float> samples, int nx,
                           int ny, std::span<float> coefficients) {
    return analyzer.ForwardDct(samples, nx, ny, coefficients);
  }
  // Its inverse (orthonormal DCT-III).
  static Status InverseDct(SpectralAnalyzer& analyzer, std::span<const float> coefficients, int nx,
                           int ny, std::span<float> samples) {
    return analyzer.InverseDct(coefficients, nx, ny, samples);
  }
  // An nx x ny block resampled to 2^ulog2 x 2^vlog2 texels in the DCT domain.
  static Status Resample(SpectralAnalyzer& analyzer, std::span<const float> samples, int nx, int ny,
                         int ulog2, int vlog2, std::span<float> texels) {
    return analyzer.Resample(samples, nx, ny, ulog2, vlog2, texels);
  }
};

}  // namespace dispex::spectral
