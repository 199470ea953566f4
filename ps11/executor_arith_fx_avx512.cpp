// The fx-profile arithmetic stage at the Avx512 level (executor_arith_fx.inc): CMakeLists.txt
// builds this file with the Avx2 level's flags and -mavx512f -mavx512dq -mavx512bw -mavx512vl on
// x86-64 only. Its products' rounding takes eight lanes a step (roundClampDoubles).
#include <cmath>
#include <cstring>
#include <type_traits>

#include <immintrin.h>

#include "ps11/executor_internal.h"

#if !defined(__AVX512F__) || !defined(__AVX512DQ__) || !defined(__AVX2__) || !defined(__FMA__)
#error "executor_arith_fx_avx512.cpp needs the Avx512 level's flags (CMakeLists.txt)"
#endif

namespace ps11::exec::avx512 {
namespace {
#include "ps11/executor_arith_fx.inc"
}  // namespace
const FxArithKernels kFxArith{&arithFxAny, &widenTexels, &narrowLanes};
}  // namespace ps11::exec::avx512
