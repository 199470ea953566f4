// The aligned-pass kernels at the Avx512 level (emu/aligned_pass_kernels.h): the vertical blends,
// the texel rows' means and deinterleave 32 lanes a step; every other kernel is the Avx2 level's.
// CMakeLists.txt builds this file with the Avx2 level's flags and AVX-512 F, DQ, BW and VL on
// x86-64 only; alignedKernels() hands the table out only where the CPU runs that level.
#if !defined(__AVX512BW__) || !defined(__AVX2__) || !defined(__FMA__)
#error "aligned_pass_avx512.cpp needs the Avx512 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include "emu/aligned_pass_kernels.h"
#include "emu/prefetch.h"

namespace emu {

namespace {

inline __m512i loadu(const void* p) { return _mm512_loadu_si512(p); }
inline void storeu(void* p, __m512i v) { _mm512_storeu_si512(p, v); }

// 32 texels (128 bytes, b g r a) as r g b a uint16 planes at out[c] + k.
inline void deinterleave32(const uint8_t* p, uint16_t* const out[4], int k) {
    // Per 128-bit lane: b0-3 g0-3 r0-3 a0-3 of its four texels; then per register the channels'
    // 16 bytes in texel order (b | g | r | a).
    const __m512i gather = _mm512_broadcast_i32x4(_mm_setr_epi8(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15));
    const __m512i order = _mm512_setr_epi32(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15);
    const __m512i x = _mm512_permutexvar_epi32(order, _mm512_shuffle_epi8(loadu(p), gather));       // texels 0-15
    const __m512i y = _mm512_permutexvar_epi32(order, _mm512_shuffle_epi8(loadu(p + 64), gather));  // 16-31
    // b0-15 b16-31 g0-15 g16-31, and r, a likewise.
    const __m512i bg = _mm512_permutex2var_epi64(x, _mm512_setr_epi64(0, 1, 8, 9, 2, 3, 10, 11), y);
    const __m512i ra = _mm512_permutex2var_epi64(x, _mm512_setr_epi64(4, 5, 12, 13, 6, 7, 14, 15), y);
    _mm512_storeu_si512(out[2] + k, _mm512_cvtepu8_epi16(_mm512_castsi512_si256(bg)));
    _mm512_storeu_si512(out[1] + k, _mm512_cvtepu8_epi16(_mm512_extracti64x4_epi64(bg, 1)));
    _mm512_storeu_si512(out[0] + k, _mm512_cvtepu8_epi16(_mm512_castsi512_si256(ra)));
    _mm512_storeu_si512(out[3] + k, _mm512_cvtepu8_epi16(_mm512_extracti64x4_epi64(ra, 1)));
}

void alignedDeinterleaveAvx512(const uint8_t* row, int count, uint16_t* const out[4]) {
    int k = 0;
    for (; k + 32 <= count; k += 32) {
        _mm_prefetch(reinterpret_cast<const char*>(row + 4 * k) + kPrefetchAhead, _MM_HINT_T0);
        _mm_prefetch(reinterpret_cast<const char*>(row + 4 * k + 64) + kPrefetchAhead, _MM_HINT_T0);
        deinterleave32(row + 4 * k, out, k);
    }
    // The last texels by the Avx2 kernel (its groups of 16, its reads within the row).
    if (k < count) {
        uint16_t* const rest[4] = {out[0] + k, out[1] + k, out[2] + k, out[3] + k};
        avx2::kAligned.deinterleave(row + 4 * k, count - k, rest);
    }
}

// Every group of 32 lanes of every channel: f(c, k) gives the vector of channel c at element k
// (reading up to 31 elements past the count: within the H rows' kHRowPad); the last lanes by a
// masked store.
template <typename F>
inline void verticalGroups(int count, int lane, int16_t* const out[4], F f) {
    int k = 0;
    for (; k + 32 <= count; k += 32)
        for (int c = 0; c < 4; ++c) _mm512_storeu_si512(out[c] + lane + k, f(c, k));
    if (k < count) {
        const __mmask32 m = __mmask32((1u << (count - k)) - 1);
        for (int c = 0; c < 4; ++c) _mm512_mask_storeu_epi16(out[c] + lane + k, m, f(c, k));
    }
}

// The 16-bit lanes the vertical blends are written over (emu/aligned_vertical.inc).
using VI = __m512i;
using VF = __m512;
inline VI add16(VI a, VI b) { return _mm512_add_epi16(a, b); }
inline VI and_(VI a, VI b) { return _mm512_and_si512(a, b); }
inline VI xor_(VI a, VI b) { return _mm512_xor_si512(a, b); }
inline VI mullo16(VI a, VI b) { return _mm512_mullo_epi16(a, b); }
inline VI madd16(VI a, VI b) { return _mm512_madd_epi16(a, b); }
inline VI packs32(VI a, VI b) { return _mm512_packs_epi32(a, b); }
inline VI unpacklo16(VI a, VI b) { return _mm512_unpacklo_epi16(a, b); }
inline VI unpackhi16(VI a, VI b) { return _mm512_unpackhi_epi16(a, b); }
inline VI unpacklo8(VI a, VI b) { return _mm512_unpacklo_epi8(a, b); }
inline VI unpackhi8(VI a, VI b) { return _mm512_unpackhi_epi8(a, b); }
inline VI packus16(VI a, VI b) { return _mm512_packus_epi16(a, b); }
inline VI set16(int16_t x) { return _mm512_set1_epi16(x); }
inline VI set32(int32_t x) { return _mm512_set1_epi32(x); }
inline VF setf(float x) { return _mm512_set1_ps(x); }
template <int S>
inline VI slli16(VI v) {
    return _mm512_slli_epi16(v, S);
}
template <int S>
inline VI srli16(VI v) {
    return _mm512_srli_epi16(v, S);
}
inline VI roundToInt(VF v) { return _mm512_cvtps_epi32(v); }
inline VF cvtf(VI v) { return _mm512_cvtepi32_ps(v); }
inline VF fmaddf(VF a, VF b, VF c) { return _mm512_fmadd_ps(a, b, c); }

// Every group of 32 lanes of every channel as 32 b g r a words at out + 4k (whole groups: up to
// 31 words past the count).
template <typename F>
inline void bytesGroups(int count, uint8_t* out, F f) {
    const __m512i firstHalf = _mm512_setr_epi64(0, 1, 8, 9, 2, 3, 10, 11);
    const __m512i secondHalf = _mm512_setr_epi64(4, 5, 12, 13, 6, 7, 14, 15);
    for (int k = 0; k < count; k += 32) {
        // packus per 128-bit lane j: b(8j .. 8j + 7) then g likewise; r and a the same.
        const __m512i bg = _mm512_packus_epi16(f(2, k), f(1, k));
        const __m512i ra = _mm512_packus_epi16(f(0, k), f(3, k));
        const __m512i bgPairs = _mm512_unpacklo_epi8(bg, _mm512_bsrli_epi128(bg, 8));  // b g b g ...
        const __m512i raPairs = _mm512_unpacklo_epi8(ra, _mm512_bsrli_epi128(ra, 8));
        const __m512i w0 = _mm512_unpacklo_epi16(bgPairs, raPairs);  // lane j: pixels 8j .. 8j + 3
        const __m512i w1 = _mm512_unpackhi_epi16(bgPairs, raPairs);  // 8j + 4 .. 8j + 7
        _mm512_storeu_si512(out + 4 * k, _mm512_permutex2var_epi64(w0, firstHalf, w1));
        _mm512_storeu_si512(out + 4 * k + 64, _mm512_permutex2var_epi64(w0, secondHalf, w1));
    }
}

// Every group of 32 lanes of every channel as 32 b g r a words (bytesGroups' order), each
// (word & keep) | set, stored at dst + 4k or (Additive) added with saturation to base's words;
// the last pixels by masked loads and stores of their words alone (neither is touched past the
// count).
template <bool Additive, typename F>
inline void storeGroups(int count, uint32_t keep, uint32_t set, const uint8_t* base, uint8_t* dst, F f) {
    const __m512i firstHalf = _mm512_setr_epi64(0, 1, 8, 9, 2, 3, 10, 11);
    const __m512i secondHalf = _mm512_setr_epi64(4, 5, 12, 13, 6, 7, 14, 15);
    const __m512i kv = _mm512_set1_epi32(int32_t(keep)), sv = _mm512_set1_epi32(int32_t(set));
    auto put = [&](int at, __m512i w, int words) {
        w = _mm512_or_si512(_mm512_and_si512(w, kv), sv);
        if (words >= 16) {
            if constexpr (Additive) w = _mm512_adds_epu8(w, _mm512_loadu_si512(base + at));
            _mm512_storeu_si512(dst + at, w);
        } else if (words > 0) {
            const __mmask16 m = __mmask16((1u << words) - 1);
            if constexpr (Additive) w = _mm512_adds_epu8(w, _mm512_maskz_loadu_epi32(m, base + at));
            _mm512_mask_storeu_epi32(dst + at, m, w);
        }
    };
    for (int k = 0; k < count; k += 32) {
        // (The lines ahead asked for: a RowSource's row and the target's come from memory.)
        for (int line = 0; line < 128; line += 64) {
            if constexpr (Additive)
                _mm_prefetch(reinterpret_cast<const char*>(base + 4 * k + line) + kPrefetchAhead, _MM_HINT_T0);
            if (!Additive || base != dst)
                _mm_prefetch(reinterpret_cast<const char*>(dst + 4 * k + line) + kPrefetchAhead, _MM_HINT_T0);
        }
        const __m512i bg = _mm512_packus_epi16(f(2, k), f(1, k));
        const __m512i ra = _mm512_packus_epi16(f(0, k), f(3, k));
        const __m512i bgPairs = _mm512_unpacklo_epi8(bg, _mm512_bsrli_epi128(bg, 8));
        const __m512i raPairs = _mm512_unpacklo_epi8(ra, _mm512_bsrli_epi128(ra, 8));
        const __m512i w0 = _mm512_unpacklo_epi16(bgPairs, raPairs);
        const __m512i w1 = _mm512_unpackhi_epi16(bgPairs, raPairs);
        put(4 * k, _mm512_permutex2var_epi64(w0, firstHalf, w1), count - k);
        put(4 * k + 64, _mm512_permutex2var_epi64(w0, secondHalf, w1), count - k - 16);
    }
}

#include "emu/aligned_vertical.inc"

}  // namespace

const AlignedKernels& avx512::alignedTable() {
    static const AlignedKernels table = [] {
        AlignedKernels k = avx2::kAligned;
        k.deinterleave = &alignedDeinterleaveAvx512;
        k.vertical = &verticalBlend;
        k.vertical12 = &verticalBlend12;
        k.verticalBytes = &verticalBytes;
        k.verticalStore = &verticalStore;
        k.meanBytes = &meanBytes;
        return k;
    }();
    return table;
}

}  // namespace emu
