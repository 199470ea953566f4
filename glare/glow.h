// Real-time glow (James & O'Rorke, GPU Gems ch. 21): the convolution kernel, exposed for tests
// and reports (the technique itself is registered in glare/technique.cpp).
#pragma once

#include <vector>

#include "glare/technique.h"

namespace glare {

// The normalised 1D kernel over −radius … +radius of the glow settings `s` (profile, radius,
// sigma_broad, sigma_narrow, narrow_share, period), as real numbers: what the passes quantise.
std::vector<double> glowKernel(const Settings& s);

}  // namespace glare
