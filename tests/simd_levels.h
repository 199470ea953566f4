// Runs the same work at every SIMD level this CPU runs (ps11/simd_dispatch.h), the level forced
// through the one override, so tests can compare the levels' results.
#pragma once

#include <catch2/catch.hpp>

#include "ps11/simd_dispatch.h"

namespace testutil {

// body(level) once per level this build and CPU run, Baseline first, with that level in force.
template <class F>
void forEachSimdLevel(F&& body) {
    for (ps11::SimdLevel level : ps11::runnableSimdLevels()) {
        const ps11::ScopedSimdLevel scoped(level);
        INFO("SIMD level " << ps11::simdLevelName(level));
        body(level);
    }
}

}  // namespace testutil
