// The fx8 fast-path kernels at the Avx2 level (ps11/simd_dispatch.h): CMakeLists.txt builds this
// file with -mavx2 -mfma -mf16c on x86-64 only; fastKernels() hands it out only where the CPU
// runs that level.
#include "ps11/executor_fast.h"

#if !defined(__AVX2__) || !defined(__FMA__)
#error "executor_fast_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "ps11/fill_lanes.h"

namespace ps11::exec::avx2 {
#define PS11_FAST_AVX2 1
#define PS11_FAST_NAME "fast-avx2"
#define PS11_FAST_AVX512 0
#include "ps11/executor_fast_kernels.inc"
#undef PS11_FAST_AVX512
#undef PS11_FAST_AVX2
#undef PS11_FAST_NAME
}  // namespace ps11::exec::avx2
