// The one CPU feature query (ps11/cpu_features.h): CPUID leaves 1 and 7 and XGETBV, so a feature
// counts only when the OS also saves the registers it needs (Intel SDM vol. 1, 14.3 "Detection of
// Intel AVX instructions"); the last cache level's size from sysfs.
#include "ps11/cpu_features.h"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <string>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <cpuid.h>
#endif

namespace ps11 {

namespace {

// The largest size among cpu0's caches as sysfs lists them ("32768K"), 0 when none is listed.
uint64_t lastLevelCache() {
    uint64_t best = 0;
    for (int i = 0; i < 8; ++i) {
        std::ifstream in("/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(i) + "/size");
        std::string text;
        if (!(in >> text) || text.empty()) continue;
        uint64_t n = 0;
        size_t k = 0;
        for (; k < text.size() && text[k] >= '0' && text[k] <= '9' && n < (uint64_t(1) << 40); ++k)
            n = n * 10 + uint64_t(text[k] - '0');
        const char unit = k < text.size() ? text[k] : ' ';
        n *= unit == 'K' ? 1024 : unit == 'M' ? 1024 * 1024 : unit == 'G' ? 1024 * 1024 * 1024 : 1;
        best = std::max(best, n);
    }
    return best;
}

CpuFeatures query() {
    CpuFeatures f;
    f.lastLevelCacheBytes = lastLevelCache();
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    unsigned a = 0, b = 0, c = 0, d = 0;
    if (!__get_cpuid(1, &a, &b, &c, &d)) return f;
    const bool osxsave = (c >> 27) & 1u, avx = (c >> 28) & 1u;
    if (!osxsave || !avx) return f;
    uint32_t lo = 0, hi = 0;
    __asm__("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
    if ((lo & 6u) != 6u) return f;  // the OS keeps SSE and AVX state
    f.fma = (c >> 12) & 1u;
    f.f16c = (c >> 29) & 1u;
    if (__get_cpuid_count(7, 0, &a, &b, &c, &d)) {
        f.avx2 = (b >> 5) & 1u;
        // F (bit 16), DQ (17), BW (30), VL (31); XCR0 bits 5-7: opmask, ZMM0-15 upper halves,
        // ZMM16-31 (Intel SDM vol. 1, 15.2 "Detection of AVX-512 Foundation instructions").
        const uint32_t need = (1u << 16) | (1u << 17) | (1u << 30) | (1u << 31);
        f.avx512 = (b & need) == need && (lo & 0xe0u) == 0xe0u;
    }
#endif
    return f;
}

}  // namespace

const CpuFeatures& cpuFeatures() {
    static const CpuFeatures features = query();
    return features;
}

}  // namespace ps11
