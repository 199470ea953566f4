// The fx8 fast-path kernels compiled for the x86-64 baseline (SSE2): the same source as the AVX2
// kernels (executor_fast_kernels.inc) over pairs of 128-bit registers, for CPUs without AVX2.
#include "ps11/executor_fast.h"

#if defined(__x86_64__)
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace ps11::exec::sse2 {
#define PS11_FAST_AVX2 0
#define PS11_FAST_NAME "sse2"
#include "ps11/executor_fast_kernels.inc"
#undef PS11_FAST_AVX2
#undef PS11_FAST_NAME
}  // namespace ps11::exec::sse2
#endif

namespace ps11::exec {
const FastKernels* fastKernelsBaseline() {
#if defined(__x86_64__)
    return &sse2::kKernels;
#else
    return nullptr;
#endif
}

const FastKernels* fastKernelsBest() {
    static const FastKernels* best = fastKernelsAvx2() ? fastKernelsAvx2() : fastKernelsBaseline();
    return best;
}
}  // namespace ps11::exec
