// What this CPU and operating system can run, queried once for the whole program (CPUID and
// XGETBV on x86-64; the cache size from Linux's sysfs). The SIMD dispatch (ps11/simd_dispatch.h)
// chooses every kernel level from here; nothing else asks it to pick code paths.
#pragma once

#include <cstdint>

namespace ps11 {

struct CpuFeatures {
    bool avx2 = false;  // AVX2 with the OS keeping the AVX state
    bool fma = false;   // FMA3 (the AVX2 kernels are built with it)
    bool f16c = false;  // VCVTPS2PH / VCVTPH2PS
    // AVX-512 F, DQ, BW and VL, with the OS keeping the opmask and ZMM state
    bool avx512 = false;
    // Bytes of the largest cache level (the last before memory); 0 when unknown. From the
    // kernel's description of cpu0's caches (Linux sysfs): CPUID's cache leaves differ between
    // vendors, and a hypervisor may pass its host's (this host's getconf says 320 MB, sysfs 32).
    uint64_t lastLevelCacheBytes = 0;
    bool avx2Fma() const { return avx2 && fma; }
};

// The query, made on the first call (thread-safe); all false off x86-64.
const CpuFeatures& cpuFeatures();

}  // namespace ps11
