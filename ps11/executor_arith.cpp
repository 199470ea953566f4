// The fx-profile arithmetic stage at the Baseline level (executor_arith_fx.inc), and the choice
// of a level's table.
#include <cmath>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "ps11/executor_internal.h"

namespace ps11::exec {

namespace baseline {
namespace {
#include "ps11/executor_arith_fx.inc"
}  // namespace
const FxArithKernels kFxArith{&arithFxAny, &widenTexels, &narrowLanes};
}  // namespace baseline

const FxArithKernels& fxArithKernels(SimdLevel level) {
#if defined(PS11_HAVE_AVX512)
    return *simdTable(level, &baseline::kFxArith, &avx2::kFxArith, &avx512::kFxArith);
#elif defined(PS11_HAVE_AVX2)
    return *simdTable(level, &baseline::kFxArith, &avx2::kFxArith);
#else
    (void)level;
    return baseline::kFxArith;
#endif
}

}  // namespace ps11::exec
