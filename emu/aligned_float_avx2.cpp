// The float row path's kernels at the Avx2 level (emu/aligned_float_kernels.h): CMakeLists.txt
// builds this file with -mavx2 -mfma -mf16c -ffp-contract=off on x86-64 only;
// floatRowKernels() hands the table out only where the CPU runs that level.
#if !defined(__AVX2__)
#error "aligned_float_avx2.cpp needs the Avx2 level's flags (CMakeLists.txt)"
#endif
#include <immintrin.h>

#include "emu/aligned_float_kernels.h"
#include "emu/lanes_avx2.h"
#include "ps11/texture.h"

namespace emu {

namespace {

// (1 − f)·a + f·b: the reference sampler's lerp, operation for operation.
inline __m256 lerp8(__m256 a, __m256 b, __m256 f) {
    return _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(1.0f), f), a), _mm256_mul_ps(f, b));
}
inline float lerp1(float a, float b, float f) { return (1.0f - f) * a + f * b; }

void lerpColumnsAvx2(const float* a, const float* b, const float* f, int n, float* out) {
    int j = 0;
    for (; j + 8 <= n; j += 8)
        _mm256_storeu_ps(out + j, lerp8(_mm256_loadu_ps(a + j), _mm256_loadu_ps(b + j), _mm256_loadu_ps(f + j)));
    for (; j < n; ++j) out[j] = lerp1(a[j], b[j], f[j]);
}

void lerpGatherAvx2(const float* d, int len, const int32_t* i0, const int32_t* i1, const float* f, int n, float* out) {
    int j = 0;
    for (; j + 8 <= n; j += 8) {
        const __m256i k0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i0 + j));
        const __m256i k1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i1 + j));
        __m256 a, b;
        const int base = i0[j];
        const __m256i r0 = _mm256_sub_epi32(k0, _mm256_set1_epi32(base));
        const __m256i r1 = _mm256_sub_epi32(k1, _mm256_set1_epi32(base));
        // Eight columns over at most eight texels from the first one's (a magnification): one
        // load and two permutes; over at most sixteen (nearly 1:1), two loads and four; else two
        // gathers.
        if (base + 8 <= len && withinEight(r0, r1)) {
            const __m256 row = _mm256_loadu_ps(d + base);
            a = _mm256_permutevar8x32_ps(row, r0);
            b = _mm256_permutevar8x32_ps(row, r1);
        } else if (base + 16 <= len && withinSixteen(r0, r1)) {
            const __m256i lo = _mm256_castps_si256(_mm256_loadu_ps(d + base));
            const __m256i hi = _mm256_castps_si256(_mm256_loadu_ps(d + base + 8));
            a = _mm256_castsi256_ps(permuteSixteen(lo, hi, r0));
            b = _mm256_castsi256_ps(permuteSixteen(lo, hi, r1));
        } else {
            a = _mm256_i32gather_ps(d, k0, 4);
            b = _mm256_i32gather_ps(d, k1, 4);
        }
        _mm256_storeu_ps(out + j, lerp8(a, b, _mm256_loadu_ps(f + j)));
    }
    for (; j < n; ++j) out[j] = lerp1(d[i0[j]], d[i1[j]], f[j]);
}

void lerpWordsAvx2(const uint8_t* row, int len, const int32_t* i0, const int32_t* i1, const float* f, int n, float* out,
                   size_t stride) {
    const __m256i byte = _mm256_set1_epi32(0xff);
    const int* words = reinterpret_cast<const int*>(row);
    int j = 0;
    for (; j + 8 <= n; j += 8) {
        const __m256i k0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i0 + j));
        const __m256i k1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(i1 + j));
        const int base = i0[j];
        const __m256i r0 = _mm256_sub_epi32(k0, _mm256_set1_epi32(base));
        const __m256i r1 = _mm256_sub_epi32(k1, _mm256_set1_epi32(base));
        __m256i wa, wb;
        // Columns i0 = base + s·j, i1 = i0 + 1 (a 2:1 or 4:1 reduction's taps): the 2s·8 words
        // loaded and their pairs taken apart by shuffles; other columns within eight texels of
        // the first: one load and two permutes; else two gathers.
        const __m256i stride2 = _mm256_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14), one = _mm256_set1_epi32(1);
        const __m256i pairs = _mm256_cmpeq_epi32(r1, _mm256_add_epi32(r0, one));
        const bool s2 =
            base + 16 <= len && _mm256_movemask_epi8(_mm256_and_si256(pairs, _mm256_cmpeq_epi32(r0, stride2))) == -1;
        const bool s4 = !s2 && base + 32 <= len &&
                        _mm256_movemask_epi8(
                            _mm256_and_si256(pairs, _mm256_cmpeq_epi32(r0, _mm256_add_epi32(stride2, stride2)))) == -1;
        if (s2 || s4) {
            // s = 2: the pairs are the 64-bit words 0..7 of v0 ‖ v1; s = 4: the even ones of
            // v0 ‖ v1 ‖ v2 ‖ v3, gathered by two 64-bit unpacks (in lane order 0 2 1 3 | 4 6 5 7).
            const __m256i* p = reinterpret_cast<const __m256i*>(words + base);
            // The row's lines ahead (a reduction streams its texel rows): one thread waits on each else.
            _mm_prefetch(reinterpret_cast<const char*>(p) + kPrefetchAhead, _MM_HINT_T0);
            if (s4) _mm_prefetch(reinterpret_cast<const char*>(p + 2) + kPrefetchAhead, _MM_HINT_T0);
            __m256 x = _mm256_castsi256_ps(_mm256_loadu_si256(p)), y = _mm256_castsi256_ps(_mm256_loadu_si256(p + 1));
            __m256i order = _mm256_setr_epi32(0, 1, 4, 5, 2, 3, 6, 7);  // a0 a1 a4 a5 | a2 a3 a6 a7 → in order
            if (s4) {
                const __m256i z = _mm256_loadu_si256(p + 2), u = _mm256_loadu_si256(p + 3);
                x = _mm256_castsi256_ps(_mm256_unpacklo_epi64(_mm256_castps_si256(x), _mm256_castps_si256(y)));
                y = _mm256_castsi256_ps(_mm256_unpacklo_epi64(z, u));
                order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);  // a0 a2 a4 a6 | a1 a3 a5 a7 → in order
            }
            wa = _mm256_permutevar8x32_epi32(_mm256_castps_si256(_mm256_shuffle_ps(x, y, _MM_SHUFFLE(2, 0, 2, 0))),
                                             order);
            wb = _mm256_permutevar8x32_epi32(_mm256_castps_si256(_mm256_shuffle_ps(x, y, _MM_SHUFFLE(3, 1, 3, 1))),
                                             order);
        } else if (base + 8 <= len && withinEight(r0, r1)) {
            const __m256i w = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(words + base));
            wa = _mm256_permutevar8x32_epi32(w, r0);
            wb = _mm256_permutevar8x32_epi32(w, r1);
        } else {
            wa = _mm256_i32gather_epi32(words, k0, 4);
            wb = _mm256_i32gather_epi32(words, k1, 4);
        }
        const __m256 fv = _mm256_loadu_ps(f + j);
        const auto channel = [&](__m256i w, int shift) {
            return unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(w, shift), byte)));
        };
        constexpr int kShift[4] = {16, 8, 0, 24};  // r g b a in a b g r a word
        for (size_t c = 0; c < 4; ++c)
            _mm256_storeu_ps(out + c * stride + size_t(j), lerp8(channel(wa, kShift[c]), channel(wb, kShift[c]), fv));
    }
    if (j < n)
        floatRowKernels(ps11::SimdLevel::Baseline)
            .lerpWords(row, len, i0 + j, i1 + j, f + j, n - j, out + size_t(j), stride);
}

bool lerpValuesAvx2(const float* rgba, int /*len*/, const int32_t* i0, const int32_t* i1, const float* f, int n,
                    float* out, size_t stride) {
    int j = 0;
    __m256 nan = _mm256_setzero_ps();
    for (; j + 8 <= n; j += 8) {
        // Columns k and k + 4 in the halves of X_k: each column's lerp of its two texels (r g b a),
        // then the four registers transposed within their halves into r, g, b, a of columns 0..7.
        const __m256 fv = _mm256_loadu_ps(f + j);
        __m256 x[4];
        for (int k = 0; k < 4; ++k) {
            const __m256 a = _mm256_loadu2_m128(rgba + 4 * size_t(i0[j + k + 4]), rgba + 4 * size_t(i0[j + k]));
            const __m256 b = _mm256_loadu2_m128(rgba + 4 * size_t(i1[j + k + 4]), rgba + 4 * size_t(i1[j + k]));
            const __m256 fk = _mm256_permutevar8x32_ps(fv, _mm256_setr_epi32(k, k, k, k, k + 4, k + 4, k + 4, k + 4));
            x[k] = lerp8(a, b, fk);
            nan = _mm256_or_ps(nan, _mm256_cmp_ps(x[k], x[k], _CMP_UNORD_Q));
        }
        const __m256 t0 = _mm256_unpacklo_ps(x[0], x[1]), t1 = _mm256_unpackhi_ps(x[0], x[1]);
        const __m256 t2 = _mm256_unpacklo_ps(x[2], x[3]), t3 = _mm256_unpackhi_ps(x[2], x[3]);
        _mm256_storeu_ps(out + size_t(j), _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)));
        _mm256_storeu_ps(out + stride + size_t(j), _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)));
        _mm256_storeu_ps(out + 2 * stride + size_t(j), _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)));
        _mm256_storeu_ps(out + 3 * stride + size_t(j), _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2)));
    }
    if (_mm256_movemask_ps(nan)) return false;
    for (; j < n; ++j)
        for (size_t c = 0; c < 4; ++c) {
            const float v = lerp1(rgba[4 * size_t(i0[j]) + c], rgba[4 * size_t(i1[j]) + c], f[j]);
            if (v != v) return false;
            out[c * stride + size_t(j)] = v;
        }
    return true;
}

void lerpRowAvx2(const float* a, const float* b, float f, int n, float* out) {
    const __m256 fv = _mm256_set1_ps(f), gv = _mm256_set1_ps(1.0f - f);
    int j = 0;
    for (; j + 8 <= n; j += 8)
        _mm256_storeu_ps(out + j, _mm256_add_ps(_mm256_mul_ps(gv, _mm256_loadu_ps(a + j)),
                                                _mm256_mul_ps(fv, _mm256_loadu_ps(b + j))));
    for (; j < n; ++j) out[j] = lerp1(a[j], b[j], f);
}

void decodeAvx2(const uint8_t* row, int n, float* out, size_t stride) {
    // float(b) / 255 is unorm8Values()[b] (unitOfByte).
    const __m256i byte = _mm256_set1_epi32(0xff);
    constexpr int kShift[4] = {16, 8, 0, 24};  // r g b a in a b g r a word
    int i = 0;
    const bool ahead = 4 * n >= kPrefetchRowBytes;
    for (; i + 8 <= n; i += 8) {
        if (ahead) _mm_prefetch(reinterpret_cast<const char*>(row + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
        const __m256i w = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + 4 * i));
        _mm256_storeu_ps(out + i, unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(w, 16), byte))));
        _mm256_storeu_ps(out + stride + i,
                         unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(w, 8), byte))));
        _mm256_storeu_ps(out + 2 * stride + i, unitOfByte(_mm256_cvtepi32_ps(_mm256_and_si256(w, byte))));
        _mm256_storeu_ps(out + 3 * stride + i, unitOfByte(_mm256_cvtepi32_ps(_mm256_srli_epi32(w, 24))));
    }
    const float* unit = ps11::Texture::unorm8Values();
    for (; i < n; ++i) {
        const uint32_t w = uint32_t(row[4 * i]) | uint32_t(row[4 * i + 1]) << 8 | uint32_t(row[4 * i + 2]) << 16 |
                           uint32_t(row[4 * i + 3]) << 24;
        for (size_t c = 0; c < 4; ++c) out[c * stride + size_t(i)] = unit[(w >> kShift[c]) & 0xffu];
    }
}

void transposeAvx2(const float* v, int n, float* out, size_t stride) {
    int i = 0;
    const bool ahead = 16 * n >= kPrefetchRowBytes;
    for (; i + 8 <= n; i += 8) {
        if (ahead) {
            _mm_prefetch(reinterpret_cast<const char*>(v + 4 * i) + kPrefetchAhead, _MM_HINT_T0);
            _mm_prefetch(reinterpret_cast<const char*>(v + 4 * i + 16) + kPrefetchAhead, _MM_HINT_T0);
        }
        // Texels 0-1 | 4-5, 2-3 | 6-7, …: each 128-bit lane a texel; then a 4×4 transpose per
        // lane (unpacks and 64-bit moves carry the bits as they are).
        const __m256 a = _mm256_loadu2_m128(v + 4 * i + 16, v + 4 * i);       // t0 | t4
        const __m256 b = _mm256_loadu2_m128(v + 4 * i + 20, v + 4 * i + 4);   // t1 | t5
        const __m256 c = _mm256_loadu2_m128(v + 4 * i + 24, v + 4 * i + 8);   // t2 | t6
        const __m256 d = _mm256_loadu2_m128(v + 4 * i + 28, v + 4 * i + 12);  // t3 | t7
        const __m256 ab0 = _mm256_unpacklo_ps(a, b), ab1 = _mm256_unpackhi_ps(a, b);  // r0 r1 g0 g1 | b0 b1 a0 a1
        const __m256 cd0 = _mm256_unpacklo_ps(c, d), cd1 = _mm256_unpackhi_ps(c, d);
        _mm256_storeu_ps(out + i, _mm256_shuffle_ps(ab0, cd0, 0x44));  // r0 r1 r2 r3 | r4 … r7
        _mm256_storeu_ps(out + stride + i, _mm256_shuffle_ps(ab0, cd0, 0xee));
        _mm256_storeu_ps(out + 2 * stride + i, _mm256_shuffle_ps(ab1, cd1, 0x44));
        _mm256_storeu_ps(out + 3 * stride + i, _mm256_shuffle_ps(ab1, cd1, 0xee));
    }
    for (; i < n; ++i)
        for (size_t c = 0; c < 4; ++c) out[c * stride + size_t(i)] = v[4 * size_t(i) + c];
}

}  // namespace

const FloatRowKernels avx2::kFloatRow{&lerpColumnsAvx2, &lerpGatherAvx2, &lerpWordsAvx2, &lerpValuesAvx2,
                                      &lerpRowAvx2,     &decodeAvx2,     &transposeAvx2};

}  // namespace emu
