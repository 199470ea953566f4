// The fx-profile arithmetic stage at the Avx2 level (executor_arith_fx.inc): CMakeLists.txt
// builds this file with -mavx2 -mfma -mf16c -ffp-contract=off on x86-64 only.
#include <cmath>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "ps11/executor_internal.h"

#if !defined(__AVX2__) || !defined(__FMA__)
#error "executor_arith_fx_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif

namespace ps11::exec::avx2 {
namespace {
#include "ps11/executor_arith_fx.inc"
}  // namespace
const FxArithKernels kFxArith{&arithFxAny, &widenTexels, &narrowLanes};
}  // namespace ps11::exec::avx2
