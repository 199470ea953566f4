// The float-profile arithmetic stage at the Avx2 level (executor_arith_float.inc): CMakeLists.txt
// builds this file with -mavx2 -mfma -mf16c -ffp-contract=off on x86-64 only.
#include <cmath>
#include <cstring>

#include "ps11/executor_internal.h"

#if !defined(__AVX2__) || !defined(__FMA__)
#error "executor_arith_float_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif

namespace ps11::exec::avx2 {
namespace {
#include "ps11/executor_arith_float.inc"
}  // namespace
const FloatArithKernels kFloatArith{&arithFloat};
}  // namespace ps11::exec::avx2
