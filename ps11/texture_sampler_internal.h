// Per-axis helpers shared by the reference sampler (texture_sampler.cpp) and the fast Unorm8
// kernels (texture_sampler_fast*.cpp): texel-space positions, 8-bit weights and the address
// modes of docs/textures.md. Everything has internal linkage (anonymous namespace) because the
// kernels are compiled twice with different instruction sets; one TU's copy must never replace
// another's at link time.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "ps11/precision.h"
#include "ps11/texture_sampler.h"

namespace ps11 {
namespace {

inline int32_t mirrorIndex(int64_t k, int64_t n) { return int32_t(k < n ? k : 2 * n - 1 - k); }

// Maps the integer texel coordinate `fl` (and fl + 1) of an axis with n texels through the
// address mode (spec §6.3). `fl` may be any double integer (huge values included); indices
// are always in [0, n) or -1 for a border texel.
template <TextureAddress Mode>
inline void addressPair(double fl, int64_t n, int32_t& i0, int32_t& i1) {
    if constexpr (Mode == TextureAddress::Wrap) {
        int64_t k = (fl > -1e15 && fl < 1e15) ? int64_t(fl) % n : int64_t(std::fmod(fl, double(n)));
        if (k < 0) k += n;
        i0 = int32_t(k);
        i1 = k + 1 == n ? 0 : int32_t(k + 1);
    } else if constexpr (Mode == TextureAddress::Mirror) {
        const int64_t p = 2 * n;  // mirror repeats every two copies
        int64_t k = (fl > -1e15 && fl < 1e15) ? int64_t(fl) % p : int64_t(std::fmod(fl, double(p)));
        if (k < 0) k += p;
        i0 = mirrorIndex(k, n);
        i1 = mirrorIndex(k + 1 == p ? 0 : k + 1, n);
    } else if constexpr (Mode == TextureAddress::Clamp) {
        int64_t k = int64_t(std::clamp(fl, -1.0, double(n)));
        i0 = int32_t(std::clamp<int64_t>(k, 0, n - 1));
        i1 = int32_t(std::clamp<int64_t>(k + 1, 0, n - 1));
    } else if constexpr (Mode == TextureAddress::Border) {
        int64_t k = int64_t(std::clamp(fl, -2.0, double(n + 1)));
        i0 = k >= 0 && k < n ? int32_t(k) : -1;
        i1 = k + 1 >= 0 && k + 1 < n ? int32_t(k + 1) : -1;
    } else {  // MirrorOnce: mirror once around 0 (texel -1 is texel 0), then clamp
        int64_t k = int64_t(std::clamp(fl, -double(n) - 2.0, double(n + 1)));
        auto once = [n](int64_t j) { return int32_t(std::clamp<int64_t>(j < 0 ? -j - 1 : j, 0, n - 1)); };
        i0 = once(k);
        i1 = once(k + 1);
    }
}

constexpr double kSmall = 1099511627776.0;  // 2^40: beyond it positions take the slow path

// Texel-space position of one coordinate: x = u*n - 0.5 for linear (texel centres, spec §6.2),
// u*n for point (floor(u*n), ties go up). Computed in double, exact for float32 u and n <= 2^14.
// NaN samples as 0, infinities as a huge finite position (never a crash).
inline void texelPosition(float u, uint32_t n, bool linear, double& fl, double& fr) {
    const double x = double(u) * double(n) - (linear ? 0.5 : 0.0);
    if (x > -kSmall && x < kSmall) {
        double r = roundEvenSmall(x);
        fl = r > x ? r - 1.0 : r;  // floor
        fr = x - fl;
        return;
    }
    fl = std::floor(x);
    fr = x - fl;
    if (!(fr >= 0.0 && fr < 1.0)) {
        fl = x > 0 ? 1e18 : x < 0 ? -1e18 : 0.0;
        fr = 0.0;
    }
}

// The 8-bit weight round_half_even(fr * 256) of a fraction fr in [0, 1).
inline int32_t weight8(double fr) { return int32_t(roundEvenSmall(fr * 256.0)); }

}  // namespace
}  // namespace ps11
