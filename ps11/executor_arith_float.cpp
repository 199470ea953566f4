// The float-profile arithmetic stage at the Baseline level (executor_arith_float.inc), and the
// choice of a level's table.
#include <cmath>
#include <cstring>

#include "ps11/executor_internal.h"

namespace ps11::exec {

namespace baseline {
namespace {
#include "ps11/executor_arith_float.inc"
}  // namespace
const FloatArithKernels kFloatArith{&arithFloat};
}  // namespace baseline

const FloatArithKernels& floatArithKernels(SimdLevel level) {
#if defined(PS11_HAVE_AVX512)
    return *simdTable(level, &baseline::kFloatArith, &avx2::kFloatArith, &avx512::kFloatArith);
#elif defined(PS11_HAVE_AVX2)
    return *simdTable(level, &baseline::kFloatArith, &avx2::kFloatArith);
#else
    (void)level;
    return baseline::kFloatArith;
#endif
}

}  // namespace ps11::exec
