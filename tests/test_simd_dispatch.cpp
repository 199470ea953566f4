// The one SIMD dispatch (ps11/simd_dispatch.h): the level names, PS11_SIMD's rule and the
// override.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "ps11/cpu_features.h"
#include "ps11/simd_dispatch.h"

using ps11::SimdLevel;

namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("simd dispatch: level names", "[simd]") {
    CHECK(std::string(ps11::simdLevelName(SimdLevel::Baseline)) == "baseline");
    CHECK(std::string(ps11::simdLevelName(SimdLevel::Avx2)) == "avx2");
    CHECK(ps11::parseSimdLevel("baseline") == SimdLevel::Baseline);
    CHECK(ps11::parseSimdLevel("avx2") == SimdLevel::Avx2);
    CHECK_FALSE(ps11::parseSimdLevel("AVX2"));
    CHECK_FALSE(ps11::parseSimdLevel("sse2"));
    CHECK_FALSE(ps11::parseSimdLevel(""));
}

TEST_CASE("simd dispatch: PS11_SIMD's rule, bad values and levels the CPU cannot run", "[simd]") {
    std::string error = "stale";
    // Unset or empty: the best level, silently.
    CHECK(ps11::simdLevelFromEnv(nullptr, SimdLevel::Avx2, error) == SimdLevel::Avx2);
    CHECK(error.empty());
    CHECK(ps11::simdLevelFromEnv("", SimdLevel::Baseline, error) == SimdLevel::Baseline);
    CHECK(error.empty());
    // A level the CPU runs.
    CHECK(ps11::simdLevelFromEnv("baseline", SimdLevel::Avx2, error) == SimdLevel::Baseline);
    CHECK(error.empty());
    CHECK(ps11::simdLevelFromEnv("avx2", SimdLevel::Avx2, error) == SimdLevel::Avx2);
    CHECK(error.empty());
    // An unknown value: the best level, and a message naming the variable and the value.
    CHECK(ps11::simdLevelFromEnv("avx512", SimdLevel::Avx2, error) == SimdLevel::Avx2);
    INFO(error);
    CHECK(contains(error, "PS11_SIMD=avx512"));
    CHECK(contains(error, "unknown SIMD level"));
    CHECK(contains(error, "using avx2"));
    CHECK(ps11::simdLevelFromEnv("Baseline", SimdLevel::Baseline, error) == SimdLevel::Baseline);
    CHECK(contains(error, "PS11_SIMD=Baseline"));
    // Avx2 on a CPU without it: Baseline, and a message.
    CHECK(ps11::simdLevelFromEnv("avx2", SimdLevel::Baseline, error) == SimdLevel::Baseline);
    CHECK(contains(error, "PS11_SIMD=avx2"));
    CHECK(contains(error, "cannot run avx2"));
    CHECK(contains(error, "using baseline"));
}

TEST_CASE("simd dispatch: the best level follows the CPU query; the override falls back to it", "[simd]") {
#ifdef PS11_HAVE_AVX2
    const ps11::CpuFeatures& f = ps11::cpuFeatures();
    const bool avx2 = f.avx2Fma() && f.f16c;
#else
    const bool avx2 = false;
#endif
    CHECK(ps11::simdLevelRuns(SimdLevel::Baseline));
    CHECK(ps11::simdLevelRuns(SimdLevel::Avx2) == avx2);
    CHECK(ps11::bestSimdLevel() == (avx2 ? SimdLevel::Avx2 : SimdLevel::Baseline));
    const std::vector<SimdLevel> levels = ps11::runnableSimdLevels();
    REQUIRE(!levels.empty());
    CHECK(levels.front() == SimdLevel::Baseline);
    CHECK(levels.back() == ps11::bestSimdLevel());

    const SimdLevel before = ps11::simdLevel();
    {
        const ps11::ScopedSimdLevel outer(SimdLevel::Baseline);
        CHECK(outer.level() == SimdLevel::Baseline);
        CHECK(ps11::simdLevel() == SimdLevel::Baseline);
        {
            // Avx2 where the CPU runs it, else Baseline.
            const ps11::ScopedSimdLevel inner(SimdLevel::Avx2);
            CHECK(inner.level() == ps11::bestSimdLevel());
            CHECK(ps11::simdLevel() == inner.level());
        }
        CHECK(ps11::simdLevel() == SimdLevel::Baseline);
    }
    CHECK(ps11::simdLevel() == before);
    CHECK(ps11::setSimdLevel(SimdLevel::Avx2) == ps11::bestSimdLevel());
    CHECK(ps11::setSimdLevel(SimdLevel::Baseline) == SimdLevel::Baseline);
    CHECK(ps11::simdLevel() == SimdLevel::Baseline);
    ps11::clearSimdLevel();
    CHECK(ps11::simdLevel() == before);
}
