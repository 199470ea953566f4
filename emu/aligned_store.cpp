// Device stage: the aligned-pass path's stores to 8-bit targets (emu/aligned_pass.h): int16 lanes
// (the SIMD level's vector kernel, then the rest one by one), words and fills, plain or additive
// (ONE/ONE ADD, each byte saturated), as the output merger stores them (emu/output_merger.cpp).
#include <algorithm>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "emu/aligned_pass.h"
#include "emu/aligned_pass_kernels.h"
#include "emu/format.h"
#include "emu/prefetch.h"

namespace emu {

namespace {

// The words' bytes added one by one, each sum saturated to 255 (ONE/ONE ADD into an 8-bit target).
inline uint32_t addBytesSaturated(uint32_t a, uint32_t b) {
    uint32_t s = 0;
    for (int k = 0; k < 4; ++k)
        s |= std::min<uint32_t>(((a >> (8 * k)) & 0xff) + ((b >> (8 * k)) & 0xff), 255u) << (8 * k);
    return s;
}

template <bool Additive>
void storeRowScalar(const int16_t* const r[4], int count, uint32_t orMask, const uint8_t* base, uint8_t* dst) {
    for (int i = 0; i < count; ++i) {
        auto b = [&](int c) { return uint32_t(std::clamp<int>(r[c][i], 0, 255)); };
        uint32_t w = b(2) | (b(1) << 8) | (b(0) << 16) | (b(3) << 24) | orMask;
        if constexpr (Additive) w = addBytesSaturated(w, load32(base + 4 * i));
        std::memcpy(dst + 4 * i, &w, 4);
    }
}

// fx12: each channel's byte of its grid value saturated to [0, 4080]; additive (ONE/ONE ADD):
// the byte of s + 16·d saturated, which is what the merger's exact blend rounds to (both factors
// one: G·(s + 16·d)·255 / G² = (s + 16·d) / 16).
// Channel by channel over the lanes (count <= kMaxSpan), in loops the compiler vectorises.
template <bool Additive>
void storeRowScalar12(const int16_t* const r[4], int count, uint32_t orMask, const uint8_t* base, uint8_t* dst) {
    alignas(32) uint32_t old[ps11::kMaxSpan], out[ps11::kMaxSpan];
    if constexpr (Additive) std::memcpy(old, base, 4 * size_t(count));
    for (int i = 0; i < count; ++i) out[i] = orMask;
    for (int c = 0; c < 4; ++c) {
        const int shift = 8 * ps11::kUnorm8Byte[c];
        const int16_t* __restrict rc = r[c];
        for (int i = 0; i < count; ++i) {
            int32_t n = rc[i] < 0 ? 0 : rc[i] > kG12 ? kG12 : rc[i];
            if constexpr (Additive) {
                n += int32_t((old[i] >> shift) & 0xffu) * 16;
                n = n > kG12 ? kG12 : n;
            }
            out[i] |= unorm8OfFx12(n) << shift;
        }
    }
    std::memcpy(dst, out, 4 * size_t(count));
}

}  // namespace

void storeLanes(const AlignedDraw& draw, const int16_t* const r[4], int n, uint32_t orMask, const uint8_t* base,
                uint8_t* row) {
    if (draw.fx12) {
        const int done = draw.kernels ? draw.kernels->storeRow12(draw.directAdd, r, n, orMask, base, row) : 0;
        const int16_t* const rest[4] = {r[0] + done, r[1] + done, r[2] + done, r[3] + done};
        if (draw.directAdd)
            storeRowScalar12<true>(rest, n - done, orMask, base + 4 * done, row + 4 * done);
        else
            storeRowScalar12<false>(rest, n - done, orMask, base + 4 * done, row + 4 * done);
        return;
    }
    int done = 0;
    if (draw.kernels) done = draw.kernels->storeRow(draw.directAdd, r, n, orMask, base, row);
    const int16_t* const rest[4] = {r[0] + done, r[1] + done, r[2] + done, r[3] + done};
    if (draw.directAdd)
        storeRowScalar<true>(rest, n - done, orMask, base + 4 * done, row + 4 * done);
    else
        storeRowScalar<false>(rest, n - done, orMask, base + 4 * done, row + 4 * done);
}

void storeWords(const uint8_t* src, int n, uint32_t keep, uint32_t set, bool additive, const uint8_t* base,
                uint8_t* dst) {
    if (!additive && keep == ~0u && set == 0) {
        std::memcpy(dst, src, size_t(n) * 4);
        return;
    }
    int i = 0;
#if defined(__SSE2__)
    const __m128i k = _mm_set1_epi32(int32_t(keep)), sv = _mm_set1_epi32(int32_t(set));
    // (One pass: the masked words are never read back from a copy just made, which the store
    // buffer cannot forward from a string move.)
    for (; i + 4 <= n; i += 4) {
        if (i % 16 == 0) {  // (a line ahead of each row read or written: a 1080p composite's come from memory)
            _mm_prefetch(reinterpret_cast<const char*>(src + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
            if (additive) _mm_prefetch(reinterpret_cast<const char*>(base + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
            if (!additive || base != dst)
                _mm_prefetch(reinterpret_cast<const char*>(dst + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        }
        __m128i w = _mm_or_si128(_mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(src + 4 * i)), k), sv);
        if (additive) w = _mm_adds_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(base + 4 * i)), w);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + 4 * i), w);
    }
#endif
    for (; i < n; ++i) {
        uint32_t w = (load32(src + 4 * i) & keep) | set;
        if (additive) w = addBytesSaturated(w, load32(base + 4 * i));
        std::memcpy(dst + 4 * i, &w, 4);
    }
}

void fillWords(const uint8_t word[4], int n, bool additive, const uint8_t* base, uint8_t* dst) {
    const uint32_t w = load32(word);
    int i = 0;
#if defined(__SSE2__)
    const __m128i v = _mm_set1_epi32(int32_t(w));
    for (; i + 4 <= n; i += 4) {
        if (i % 16 == 0) {  // (as storeWords)
            if (additive) _mm_prefetch(reinterpret_cast<const char*>(base + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
            if (!additive || base != dst)
                _mm_prefetch(reinterpret_cast<const char*>(dst + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        }
        __m128i out = v;
        if (additive) out = _mm_adds_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(base + 4 * i)), v);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + 4 * i), out);
    }
#endif
    for (; i < n; ++i) {
        const uint32_t out = additive ? addBytesSaturated(w, load32(base + 4 * i)) : w;
        std::memcpy(dst + 4 * i, &out, 4);
    }
}

}  // namespace emu
