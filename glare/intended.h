// The intended math of the techniques that approximate one (docs/bench.md "Intended math"): what
// the effect would be without the era's shortcuts, as a float computation on the CPU, for
// `ps11 bench` to measure a technique's output against. The pyramid approximates a sum of true 5-,
// 11-, 21- and 41-tap Gaussians (GLARE.md §3); the glow a convolution of its glow sources with its
// 1D profile at full resolution (GLARE.md §2, docs/glare/glow.md).
#pragma once

#include <optional>
#include <string>

#include "emu/image_file.h"
#include "glare/technique.h"

namespace glare {

// The final frame (RGB in [0, 1], alpha 1) the technique `t` with `settings` intends for `input`
// at frame index `frame` of a sequence with a still input; nullopt for a technique (or settings:
// the glow's after-image `feedback`) without a stated intended result, with `why` saying so.
std::optional<emu::FloatImage> intendedResult(const Technique& t, const Settings& settings, const emu::FloatImage& input,
                                              int frame, std::string& why);

// Separable convolution of the RGB of `image` with a normalised 1D kernel (odd length, centred),
// horizontally and vertically, edges clamped (the techniques' CLAMP addressing). Alpha untouched.
void convolveRgb(emu::FloatImage& image, const std::vector<double>& kernel);

// A sampled Gaussian of standard deviation `sigma` over −radius … +radius, normalised to sum 1.
std::vector<double> gaussianKernel(double sigma, int radius);

}  // namespace glare
