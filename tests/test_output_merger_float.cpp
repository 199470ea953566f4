// The output merger into float targets (emu/output_merger_float.cpp, docs/output-merger.md):
// stores (half rounding for A16B16G16R16F), blending in float32 without clamping, constant-factor
// blends of row runs at every SIMD level, and the half conversion against format.cpp.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "emu/format.h"
#include "emu/output_merger.h"
#include "output_merger_model.h"
#include "ps11/simd_dispatch.h"
#include "simd_levels.h"

using namespace emu;
using ps11::Precision;

using namespace mergermodel;

// ---- float targets --------------------------------------------------------------------------

TEST_CASE("merger: float targets store the value (half rounding for A16B16G16R16F)", "[merger]") {
    std::mt19937 rng(99);
    for (Precision p : {Precision::Fx8, Precision::Fx12, Precision::Float, Precision::Ideal}) {
        MergeState st;
        st.precision = p;
        Image f32 = makeImage(D3DFMT_A32B32G32R32F, 16, 16);
        Image f16 = makeImage(D3DFMT_A16B16G16R16F, 16, 16);
        Image r32 = makeImage(D3DFMT_R32F, 16, 16);
        Span span(256);
        const int32_t G = ps11::gridScale(p);
        for (int i = 0; i < 256; ++i) {
            if (ps11::isFixedPoint(p)) {
                std::array<int32_t, 4> n;
                for (int c = 0; c < 4; ++c) n[size_t(c)] = int32_t(rng() % (16u * G)) - 8 * G;  // within +-8 (ps_1_4)
                span.setGrid(i, n, p);
            } else {
                std::array<float, 4> v;
                for (int c = 0; c < 4; ++c)
                    v[size_t(c)] = std::ldexp(float(int32_t(rng() % 2000001u) - 1000000) / 1e6f, int(rng() % 40) - 24);
                if (i == 0) v = {70000.0f, -65519.0f, 1e-7f, 6.1e-5f};
                span.setColor(i, v);
            }
        }
        run(st, span, &f32);
        run(st, span, &f16);
        run(st, span, &r32);
        for (int i = 0; i < 256; ++i) {
            const uint32_t x = uint32_t(i % 16), y = uint32_t(i / 16);
            for (int c = 0; c < 4; ++c) {
                const float v = span.color[c][size_t(i)];
                CHECK(floatAt(f32, x, y, c) == v);
                CHECK(halfAt(f16, x, y, c) == floatToHalf(v));  // format.cpp's converter, independent
            }
            CHECK(floatAt(r32, x, y, 0) == span.color[0][size_t(i)]);
        }
    }
}

TEST_CASE("merger: float targets blend in float32 without clamping", "[merger]") {
    for (D3DBLENDOP op : kAllOps)
        for (D3DBLEND f : kAllBlends) {
            MergeState st = blendState(f, D3DBLEND_SRCCOLOR, op, Precision::Ideal);
            st.blendFactor = 0xff00ff00u;  // exact 0 / 1
            Image img = makeImage(D3DFMT_A32B32G32R32F, 16, 1);
            Image half = makeImage(D3DFMT_A16B16G16R16F, 16, 1);
            Span span(4);
            const std::array<float, 4> src[4] = {{0.5f, 2.0f, -1.0f, 0.25f},
                                                 {3.0f, 0.125f, 0.0f, 1.5f},
                                                 {1.0f, 1.0f, 1.0f, 0.75f},
                                                 {-0.5f, 4.0f, 0.5f, 0.0f}};
            const std::array<float, 4> dst[4] = {{0.25f, 1.0f, 8.0f, 0.5f},
                                                 {0.0f, 0.5f, 2.0f, 1.0f},
                                                 {1.5f, -2.0f, 0.0f, 0.25f},
                                                 {4.0f, 0.75f, 0.125f, 2.0f}};
            for (int i = 0; i < 4; ++i) {
                span.setColor(i, src[i]);
                std::memcpy(img.texel(uint32_t(i), 0), dst[i].data(), 16);
                for (int c = 0; c < 4; ++c) {
                    const uint16_t h = floatToHalf(dst[i][size_t(c)]);
                    std::memcpy(half.texel(uint32_t(i), 0) + 2 * c, &h, 2);
                }
            }
            run(st, span, &img);
            run(st, span, &half);
            for (int i = 0; i < 4; ++i) {
                Q s[4], d[4];
                for (int c = 0; c < 4; ++c) s[c] = fromFloat(src[i][size_t(c)]), d[c] = fromFloat(dst[i][size_t(c)]);
                const std::array<Q, 4> r = blendRef(st, s, d);
                for (int c = 0; c < 4; ++c) {
                    // Small dyadic values: float32 is exact, so the rational result is the float.
                    INFO("op " << int(op) << " f " << int(f) << " lane " << i << " c " << c);
                    CHECK(fromFloat(floatAt(img, uint32_t(i), 0, c)) == r[size_t(c)]);
                    CHECK(fromFloat(halfToFloat(halfAt(half, uint32_t(i), 0, c))) == r[size_t(c)]);
                }
            }
        }
}

TEST_CASE("merger: constant-factor blends of row runs into float targets equal the per-pixel blend", "[merger][simd]") {
    // A row run with no live mask takes the run's blend (eight pixels a group at Avx2, a group
    // with a NaN pixel by pixel); the same span with a live mask of ones takes the general
    // per-pixel blend. Bit for bit, NaNs included, at every SIMD level and run length.
    std::mt19937 rng(7);
    const float specials[] = {NAN, -NAN, INFINITY, -INFINITY, -0.0f, 0.0f, 1.0f, 2.5f, -1.0f, 1e-30f};
    const D3DBLEND factors[] = {D3DBLEND_ZERO, D3DBLEND_ONE, D3DBLEND_BLENDFACTOR, D3DBLEND_INVBLENDFACTOR};
    testutil::forEachSimdLevel([&](ps11::SimdLevel) {
        for (int round = 0; round < 60; ++round) {
            INFO("round " << round);
            const Precision p = round % 2 ? Precision::Float : Precision::Ideal;
            MergeState st = blendState(factors[rng() % 4], factors[rng() % 4], D3DBLENDOP_ADD, p);
            st.blendFactor = rng();
            st.colorWrite = round % 4 == 0 ? DWORD(rng() % 16) : 0xfu;
            const int lanes = 1 + int(rng() % 64);  // groups of eight and a tail
            const int x0 = int(rng() % 8);
            Span span(lanes);
            const int nanEvery = round % 3 == 0 ? 0 : 2 + round % 20;  // none, or now and then
            auto value = [&] {
                if (nanEvery && rng() % uint32_t(nanEvery * 4) == 0) return specials[rng() % 10];
                return float(int(rng() % 3000) - 500) / 256.0f;
            };
            for (int i = 0; i < lanes; ++i) {
                span.x[size_t(i)] = x0 + i, span.y[size_t(i)] = 1;
                span.setColor(i, {value(), value(), value(), value()});
            }
            Image run = makeImage(D3DFMT_A32B32G32R32F, 80, 2), pixels = makeImage(D3DFMT_A32B32G32R32F, 80, 2);
            for (size_t b = 0; b < run.bytes.size(); b += 4) {
                const float v = value();
                std::memcpy(&run.bytes[b], &v, 4);
                std::memcpy(&pixels.bytes[b], &v, 4);
            }
            MergeInputs in = span.inputs(false);
            in.live = nullptr;
            in.row = true;
            MergeStats a, b;
            mergePixels(st, in, MergeTarget{&run, nullptr}, &a);
            mergePixels(st, span.inputs(false), MergeTarget{&pixels, nullptr}, &b);
            CHECK(a.written == b.written);
            CHECK(std::vector<uint8_t>(run.bytes.begin(), run.bytes.end()) ==
                  std::vector<uint8_t>(pixels.bytes.begin(), pixels.bytes.end()));
        }
    });
}

TEST_CASE("merger: half conversion matches format.cpp for every half and a float sweep", "[merger]") {
    // Every half pattern decoded by format.cpp, stored through the merger, must come back bit
    // for bit (NaNs: still NaN).
    // At every SIMD level this CPU runs (the plain store converts with F16C at Avx2, by bit
    // manipulation at Baseline), and through the general loop (software conversion; an ALWAYS
    // alpha test routes the pixels there).
    for (ps11::SimdLevel level : ps11::runnableSimdLevels())
        for (bool general : {false, true}) {
            const ps11::ScopedSimdLevel scoped(level);
            INFO("SIMD level " << ps11::simdLevelName(level) << (general ? ", general loop" : ", plain store"));
            MergeState st;
            st.precision = Precision::Float;
            st.alphaTest = general, st.alphaFunc = D3DCMP_ALWAYS;
            Image img = makeImage(D3DFMT_A16B16G16R16F, 16, 16);
            for (uint32_t base = 0; base < 65536; base += 1024) {
                Span span(256);
                for (int i = 0; i < 256; ++i) {
                    std::array<float, 4> v;
                    for (int c = 0; c < 4; ++c) v[size_t(c)] = halfToFloat(uint16_t(base + uint32_t(i) * 4 + uint32_t(c)));
                    span.setColor(i, v);
                }
                run(st, span, &img);
                for (int i = 0; i < 256; ++i)
                    for (int c = 0; c < 4; ++c) {
                        const uint16_t h = uint16_t(base + uint32_t(i) * 4 + uint32_t(c));
                        const uint16_t got = halfAt(img, uint32_t(i % 16), uint32_t(i / 16), c);
                        if ((h & 0x7c00) == 0x7c00 && (h & 0x3ff))
                            CHECK(((got & 0x7c00) == 0x7c00 && (got & 0x3ff)));
                        else
                            CHECK(got == h);
                    }
            }
            // Floats between halves, including exact ties and the overflow boundary.
            std::mt19937 rng(5);
            for (int round = 0; round < 64; ++round) {
                Span span(256);
                for (int i = 0; i < 256; ++i) {
                    std::array<float, 4> v;
                    for (int c = 0; c < 4; ++c) {
                        uint32_t bits = rng();
                        if (c == 0) bits = (bits & 0x80000000u) | (0x33000000u + (bits % 0x14800000u));  // 2^-25 .. 65536+
                        if (c == 1) bits = (bits & 0xffffe000u) | 0x1000u;                               // exact half-way
                        float f;
                        std::memcpy(&f, &bits, 4);
                        v[size_t(c)] = f;
                    }
                    if (i == 0) v = {65519.996f, 65520.0f, -65504.0f, 5.9604645e-8f * 0.5f};
                    span.setColor(i, v);
                }
                run(st, span, &img);
                for (int i = 0; i < 256; ++i)
                    for (int c = 0; c < 4; ++c) {
                        const float f = span.color[c][size_t(i)];
                        if (std::isnan(f)) continue;
                        CHECK(halfAt(img, uint32_t(i % 16), uint32_t(i / 16), c) == floatToHalf(f));
                    }
            }
        }
}
