// The SIMD level in force (ps11/simd_dispatch.h): the CPU's best from ps11::cpuFeatures, PS11_SIMD
// read once, and a process-wide override.
#include "ps11/simd_dispatch.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>

#include "ps11/cpu_features.h"

namespace ps11 {

namespace {

constexpr int kNoOverride = -1;
std::atomic<int> g_override{kNoOverride};

// PS11_SIMD, read and reported on the first call.
SimdLevel envLevel() {
    std::string error;
    const SimdLevel level = simdLevelFromEnv(std::getenv(kSimdEnvVar), bestSimdLevel(), error);
    if (!error.empty()) std::fprintf(stderr, "%s\n", error.c_str());
    return level;
}

}  // namespace

constexpr SimdLevel kLevels[] = {SimdLevel::Baseline, SimdLevel::Avx2, SimdLevel::Avx512};

const char* simdLevelName(SimdLevel level) {
    return level == SimdLevel::Avx512 ? "avx512" : level == SimdLevel::Avx2 ? "avx2" : "baseline";
}

std::optional<SimdLevel> parseSimdLevel(std::string_view name) {
    for (SimdLevel l : kLevels)
        if (name == simdLevelName(l)) return l;
    return std::nullopt;
}

bool simdLevelRuns(SimdLevel level) {
    if (level == SimdLevel::Baseline) return true;
#ifdef PS11_HAVE_AVX2
    const CpuFeatures& f = cpuFeatures();
    const bool avx2 = f.avx2Fma() && f.f16c;
    if (level == SimdLevel::Avx2) return avx2;
#ifdef PS11_HAVE_AVX512
    return avx2 && f.avx512;
#else
    return false;
#endif
#else
    return false;
#endif
}

SimdLevel bestSimdLevel() {
    SimdLevel best = SimdLevel::Baseline;
    for (SimdLevel l : kLevels)
        if (simdLevelRuns(l)) best = l;
    return best;
}

std::vector<SimdLevel> runnableSimdLevels() {
    std::vector<SimdLevel> levels;
    for (SimdLevel l : kLevels)
        if (simdLevelRuns(l)) levels.push_back(l);
    return levels;
}

SimdLevel simdLevelFromEnv(const char* value, SimdLevel best, std::string& error) {
    error.clear();
    if (!value || !*value) return best;
    const std::optional<SimdLevel> asked = parseSimdLevel(value);
    const std::string prefix = std::string("ps11: ") + kSimdEnvVar + "=" + value + ": ";
    if (!asked) {
        error = prefix + "unknown SIMD level (expected baseline, avx2 or avx512); using " + simdLevelName(best);
        return best;
    }
    if (*asked > best) {
        error = prefix + "this CPU or build cannot run " + simdLevelName(*asked) + " (it needs AVX2, FMA and F16C" +
                (*asked == SimdLevel::Avx512 ? ", and AVX-512 F, DQ, BW and VL" : "") + "); using " +
                simdLevelName(best);
        return best;
    }
    return *asked;
}

SimdLevel simdLevel() {
    const int o = g_override.load(std::memory_order_relaxed);
    if (o != kNoOverride) return SimdLevel(o);
    static const SimdLevel fromEnv = envLevel();
    return fromEnv;
}

SimdLevel setSimdLevel(SimdLevel level) {
    const SimdLevel taken = simdLevelRuns(level) ? level : bestSimdLevel();
    g_override.store(int(taken), std::memory_order_relaxed);
    return taken;
}

void clearSimdLevel() { g_override.store(kNoOverride, std::memory_order_relaxed); }

ScopedSimdLevel::ScopedSimdLevel(SimdLevel level)
    : m_previous(g_override.load(std::memory_order_relaxed)), m_level(setSimdLevel(level)) {}

ScopedSimdLevel::~ScopedSimdLevel() { g_override.store(m_previous, std::memory_order_relaxed); }

}  // namespace ps11
