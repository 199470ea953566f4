// SIMD dispatch: the one way the project picks between builds of its kernels (docs/architecture.md
// "SIMD dispatch"). Each SIMD family (executor fx8 kernels, float arithmetic, fast sampler,
// aligned-pass filters, output-merger half store) has a table of function pointers per level,
// and its callers fetch the table for simdLevel() once per draw, run or span. The level is the
// best this CPU runs (ps11::cpuFeatures), or what PS11_SIMD or setSimdLevel / ScopedSimdLevel ask
// for. Every level gives bit-identical results; tests run the same work at each.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ps11 {

// Baseline: what any x86-64 CPU runs (SSE2), or portable C++ on other targets.
// Avx2: AVX2, FMA and F16C, the instruction sets the *_avx2.cpp files are compiled for (x86-64
// builds only; CMakeLists.txt defines PS11_HAVE_AVX2 there).
// Avx512: Avx2's and AVX-512 F, DQ, BW and VL, for the *_avx512.cpp files (PS11_HAVE_AVX512); a
// family without an Avx512 table runs its Avx2 one there.
enum class SimdLevel : uint8_t { Baseline, Avx2, Avx512 };

// The environment variable that forces a level (read once, on the first simdLevel() call).
constexpr const char* kSimdEnvVar = "PS11_SIMD";

// "baseline", "avx2", "avx512": the names PS11_SIMD takes.
const char* simdLevelName(SimdLevel level);
std::optional<SimdLevel> parseSimdLevel(std::string_view name);

// True when this build and this CPU run `level`.
bool simdLevelRuns(SimdLevel level);
// The best level this build and CPU run.
SimdLevel bestSimdLevel();
// The levels this build and CPU run, Baseline first (tests compare them).
std::vector<SimdLevel> runnableSimdLevels();

// The level kernels use now: the override if one is set, else PS11_SIMD if it names a level
// this CPU runs, else bestSimdLevel().
SimdLevel simdLevel();

// Sets the process-wide override (tests, benchmarks) and returns the level it took: a level
// the CPU cannot run gives the best it can. clearSimdLevel() drops the override.
SimdLevel setSimdLevel(SimdLevel level);
void clearSimdLevel();

// The override for a scope; restores the previous override (or none) on exit.
class ScopedSimdLevel {
public:
    explicit ScopedSimdLevel(SimdLevel level);
    ~ScopedSimdLevel();
    ScopedSimdLevel(const ScopedSimdLevel&) = delete;
    ScopedSimdLevel& operator=(const ScopedSimdLevel&) = delete;
    SimdLevel level() const { return m_level; }  // the level in force (after any fallback)

private:
    int m_previous;
    SimdLevel m_level;
};

// PS11_SIMD's rule on its own (no environment, no stderr): the level for `value` (null or empty:
// unset) on a CPU whose best level is `best`. An unknown name, or a level above `best`, gives
// `best` and sets `error` to the message simdLevel() prints on stderr; else `error` is cleared.
SimdLevel simdLevelFromEnv(const char* value, SimdLevel best, std::string& error);

// A family's table at `level`: the highest of its tables (non-null where the build has it) at or
// below the level: `avx512` at Avx512, `avx2` at Avx2 and above, else `baseline` (null where the
// family has no kernels at that level).
template <class Kernels>
const Kernels* simdTable(SimdLevel level, const Kernels* baseline, const Kernels* avx2,
                         const Kernels* avx512 = nullptr) {
    if (level >= SimdLevel::Avx512 && avx512) return avx512;
    return level >= SimdLevel::Avx2 && avx2 ? avx2 : baseline;
}

// A table that code compiled for `tableLevel` makes on first use (`make`): made and handed out
// only where `level` asks for it and this CPU runs that level, else null (simdTable then falls
// back). Its making may run that level's instructions (a copy of another table through its
// registers), which a CPU without them stops on.
template <class Kernels>
const Kernels* madeTable(SimdLevel level, SimdLevel tableLevel, const Kernels& (*make)()) {
    return level >= tableLevel && simdLevelRuns(tableLevel) ? &make() : nullptr;
}

}  // namespace ps11
