// The fx8 fast-path kernels at the Avx512 level (ps11/simd_dispatch.h): CMakeLists.txt builds
// this file with the Avx2 level's flags and -mavx512f -mavx512dq -mavx512bw -mavx512vl on x86-64
// only; fastKernels() hands it out only where the CPU runs that level. 32 int16 lanes a step.
#include "ps11/executor_fast.h"

#if !defined(__AVX512BW__) || !defined(__AVX512DQ__) || !defined(__AVX2__) || !defined(__FMA__)
#error "executor_fast_avx512.cpp needs the Avx512 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "ps11/fill_lanes.h"

namespace ps11::exec::avx512 {
#define PS11_FAST_AVX512 1
#define PS11_FAST_AVX2 0
#define PS11_FAST_NAME "fast-avx512"
#include "ps11/executor_fast_kernels.inc"
#undef PS11_FAST_AVX512
#undef PS11_FAST_AVX2
#undef PS11_FAST_NAME
}  // namespace ps11::exec::avx512
