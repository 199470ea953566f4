// Adaptive glare (Sousa, ShaderX3 4.2): what the technique computes on the CPU, exposed for tests
// and the stress suite (the technique itself is registered in glare/technique.cpp).
#pragma once

namespace glare {

// The dither offset (a value on the 8-bit grid, within ±0.5/smoothing levels) that the
// `dither=temporal` setting adds to frame `frame`'s luminance before the smoothing blend.
double adaptationDither(int frame, double smoothing);

}  // namespace glare
