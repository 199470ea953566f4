// The fx8 fast-path kernels compiled for AVX2 (+FMA): CMakeLists.txt gives this file -mavx2 -mfma.
// Only called after fastKernelsAvx2() has checked the CPU (executor_fast.cpp).
#include "ps11/cpu_features.h"
#include "ps11/executor_fast.h"

#if defined(__x86_64__) && defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace ps11::exec::avx2 {
#define PS11_FAST_AVX2 1
#define PS11_FAST_NAME "avx2"
#include "ps11/executor_fast_kernels.inc"
#undef PS11_FAST_AVX2
#undef PS11_FAST_NAME
}  // namespace ps11::exec::avx2
#define PS11_HAVE_AVX2_KERNELS 1
#endif

namespace ps11::exec {
const FastKernels* fastKernelsAvx2() {
#ifdef PS11_HAVE_AVX2_KERNELS
    return cpuFeatures().avx2Fma() ? &avx2::kKernels : nullptr;
#else
    return nullptr;
#endif
}
}  // namespace ps11::exec
