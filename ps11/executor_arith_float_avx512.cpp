// The float-profile arithmetic stage at the Avx512 level (executor_arith_float.inc): CMakeLists.txt
// builds this file with the Avx2 level's flags and -mavx512f -mavx512dq -mavx512bw -mavx512vl on
// x86-64 only (sixteen lanes a step where the compiler vectorises; no FMA contraction, so the
// same floats as every level).
#include <cmath>
#include <cstring>

#include "ps11/executor_internal.h"

#if !defined(__AVX512F__) || !defined(__AVX2__) || !defined(__FMA__)
#error "executor_arith_float_avx512.cpp needs the Avx512 level's flags (CMakeLists.txt)"
#endif

namespace ps11::exec::avx512 {
namespace {
#include "ps11/executor_arith_float.inc"
}  // namespace
const FloatArithKernels kFloatArith{&arithFloat};
}  // namespace ps11::exec::avx512
