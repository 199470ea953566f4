// The fx8 fast-path kernels at the Baseline level (any x86-64: SSE2): the same source as the
// AVX2 kernels (executor_fast_kernels.inc) over pairs of 128-bit registers.
#include "ps11/executor_fast.h"

#if defined(__x86_64__)
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "ps11/fill_lanes.h"

namespace ps11::exec::sse2 {
#define PS11_FAST_AVX2 0
#define PS11_FAST_NAME "fast-sse2"
#define PS11_FAST_AVX512 0
#include "ps11/executor_fast_kernels.inc"
#undef PS11_FAST_AVX512
#undef PS11_FAST_AVX2
#undef PS11_FAST_NAME
}  // namespace ps11::exec::sse2
#endif
