// The output merger's stores without blending (emu/output_merger.*, docs/output-merger.md): 8-bit
// stores per profile, colour write masks, and vertex fog on 8-bit and float targets, against the
// exact model of output_merger_model.h.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>

#include "emu/output_merger.h"
#include "output_merger_model.h"

using namespace emu;
using ps11::Precision;

using namespace mergermodel;

// ---- stores without blending ------------------------------------------------------------------

TEST_CASE("merger: 8-bit stores per profile (saturate, then the nearest byte)", "[merger]") {
    Image img = makeImage(D3DFMT_A8R8G8B8, 16, 1);
    MergeState st;
    SECTION("fx8 takes the grid integers") {
        Span span(2);
        span.setGrid(0, {0, 255, 128, 77}, Precision::Fx8);
        span.setGrid(1, {-3, 300, 1, 254}, Precision::Fx8);
        run(st, span, &img);
        CHECK(rgbaAt(img, 0, 0) == std::array<uint32_t, 4>{0, 255, 128, 77});
        CHECK(rgbaAt(img, 1, 0) == std::array<uint32_t, 4>{0, 255, 1, 254});
    }
    SECTION("fx8 without grid values rounds the real values to the grid") {
        Span span(1);
        span.setColor(0, {0.5f, 1.5f, -0.25f, 0.25f});  // 127.5 -> 128, 63.75 -> 64
        MergeStats stats;
        MergeInputs in = span.inputs(false);
        mergePixels(st, in, MergeTarget{&img, nullptr}, &stats);
        CHECK(rgbaAt(img, 0, 0) == std::array<uint32_t, 4>{128, 255, 0, 64});
    }
    SECTION("float and ideal: round_half_even(sat(x) * 255)") {
        for (Precision p : {Precision::Float, Precision::Ideal}) {
            st.precision = p;
            Span span(256);
            for (int i = 0; i < 256; ++i) {
                const float v = float(i - 20) / 200.0f;  // covers < 0, > 1 and many fractions
                span.setColor(i, {v, v * 0.5f, 1.0f - v, float(2 * i + 1) / 510.0f});  // alpha: exact ties (k + 0.5)
            }
            Image big = makeImage(D3DFMT_A8R8G8B8, 16, 16);
            run(st, span, &big);
            for (int i = 0; i < 256; ++i) {
                const auto got = rgbaAt(big, uint32_t(i % 16), uint32_t(i / 16));
                for (int c = 0; c < 4; ++c) CHECK(got[size_t(c)] == byteOfQ(fromFloat(span.color[c][size_t(i)])));
            }
        }
    }
}

TEST_CASE("merger: colour write masks", "[merger]") {
    for (Precision p : {Precision::Fx8, Precision::Fx12, Precision::Float})
        for (uint32_t mask = 0; mask < 16; ++mask)
            for (bool blend : {false, true}) {
                MergeState st = blendState(D3DBLEND_ONE, D3DBLEND_ONE, D3DBLENDOP_ADD, p);
                st.blend = blend;
                st.colorWrite = mask;
                Image img = makeImage(D3DFMT_A8R8G8B8, 16, 1);
                setRgba(img, 0, 0, {11, 22, 33, 44});
                Span span(1);
                span.setGrid(0, {51 * ps11::gridScale(p) / 255, 0, ps11::gridScale(p), ps11::gridScale(p) / 255},
                             p == Precision::Float ? Precision::Fx8 : p);
                if (p == Precision::Float) span.setColor(0, {0.2f, 0.0f, 1.0f, 1.0f / 255.0f});
                run(st, span, &img);
                const std::array<uint32_t, 4> newv =
                    blend ? std::array<uint32_t, 4>{62, 22, 255, 45} : std::array<uint32_t, 4>{51, 0, 255, 1};
                const std::array<uint32_t, 4> old{11, 22, 33, 44};
                const auto got = rgbaAt(img, 0, 0);
                for (int c = 0; c < 4; ++c) {
                    INFO("mask " << mask << " blend " << blend << " c " << c);
                    CHECK(got[size_t(c)] == ((mask >> c & 1u) ? newv[size_t(c)] : old[size_t(c)]));
                }
            }
}

// ---- fog ------------------------------------------------------------------------------------

TEST_CASE("merger: vertex fog lerps rgb toward FOGCOLOR by the fog factor", "[merger]") {
    MergeState st;
    st.fog = true;
    st.fogColor = 0x20c86400u;  // a 0x20 (ignored), r 200, g 100, b 0
    const Q fogC[3] = {mk(200, 255), mk(100, 255), mk(0, 255)};
    const float factors[] = {0.0f, 1.0f, 0.5f, 0.25f, 0.3f, 0.75f, -1.0f, 2.0f};
    for (Precision p : {Precision::Fx8, Precision::Fx12, Precision::Float}) {
        st.precision = p;
        const int32_t G = ps11::gridScale(p);
        Image img = makeImage(D3DFMT_A8R8G8B8, 16, 1);
        Span span(8);
        for (int i = 0; i < 8; ++i) {
            span.fog[size_t(i)] = factors[i];
            if (p == Precision::Float)
                span.setColor(i, {0.5f, 0.125f, 1.0f, 0.75f});
            else
                span.setGrid(i, {G / 3, G / 5, G, 3 * G / 4}, p);
        }
        run(st, span, &img);
        for (int i = 0; i < 8; ++i) {
            const float f = std::clamp(factors[i], 0.0f, 1.0f);
            const auto got = rgbaAt(img, uint32_t(i), 0);
            for (int c = 0; c < 3; ++c) {
                uint32_t want;
                if (p == Precision::Float) {
                    // float32 evaluation as written: f * c + (1 - f) * fog (exact for these values
                    // except f = 0.3, whose float error stays far from a rounding boundary).
                    const Q fq = fromFloat(f), s = fromFloat(span.color[c][0]);
                    want = byteOfQ(fq * s + (kOneQ - fq) * fogC[c]);
                } else {
                    // fx: the factor on the grid (round_half_even(f * G)), the lerp exact, one
                    // rounding to the grid, then the 8-bit store.
                    const int64_t fg = rhe(fromFloat(f) * Q{G, 1});
                    const Q s = mk(span.grid[c][0], G);
                    const int64_t n = rhe((mk(fg, G) * s + mk(G - fg, G) * fogC[c]) * Q{G, 1});
                    want = byteOfQ(mk(n, G));
                }
                INFO("profile " << ps11::precisionName(p) << " f " << factors[i] << " c " << c);
                CHECK(got[size_t(c)] == want);
            }
            // Alpha is untouched by fog.
            const uint32_t alphaWant =
                p == Precision::Float ? 191u : byteOfQ(mk(span.grid[3][0], G));  // 0.75 * 255 = 191.25
            CHECK(got[3] == alphaWant);
        }
    }
    // A worked example (docs/output-merger.md): fx8, f = 0.5 -> 128/255; r = 100, fog r = 200:
    // (128 * 100 + 127 * 200) / 255 = 149.8 -> 150.
    Image img = makeImage(D3DFMT_A8R8G8B8, 16, 1);
    Span span(1);
    span.setGrid(0, {100, 100, 100, 255}, Precision::Fx8);
    span.fog[0] = 0.5f;
    st.precision = Precision::Fx8;
    run(st, span, &img);
    CHECK(rgbaAt(img, 0, 0)[0] == 150);
}

TEST_CASE("merger: fog on float targets works on the unclamped value", "[merger]") {
    MergeState st;
    st.fog = true;
    st.fogColor = 0x00ff0000u;  // r 255, g 0, b 0: exact as floats
    for (Precision p : {Precision::Fx8, Precision::Fx12, Precision::Ideal}) {
        st.precision = p;
        const int32_t G = ps11::gridScale(p);
        Image img = makeImage(D3DFMT_A32B32G32R32F, 16, 1);
        Span span(3);
        const float fs[3] = {0.25f, 0.5f, 0.75f};
        for (int i = 0; i < 3; ++i) {
            span.fog[size_t(i)] = fs[i];
            if (p == Precision::Ideal)
                span.setColor(i, {3.0f, -1.5f, 0.5f, 2.0f});
            else
                span.setGrid(i, {2 * G, -G / 2 - 1, G / 3, 2 * G}, p);  // ps_1_4 range
        }
        run(st, span, &img);
        const Q fog[3] = {kOneQ, kZeroQ, kZeroQ};
        for (int i = 0; i < 3; ++i)
            for (int c = 0; c < 4; ++c) {
                Q want;
                if (c == 3) {
                    want = p == Precision::Ideal ? Q{2, 1} : mk(span.grid[3][0], G);
                } else if (p == Precision::Ideal) {
                    const Q f = fromFloat(fs[i]);  // dyadic: float32 is exact here
                    want = f * fromFloat(span.color[c][0]) + (kOneQ - f) * fog[c];
                } else {
                    const int64_t fg = rhe(fromFloat(fs[i]) * Q{G, 1});
                    const Q sv = mk(span.grid[c][0], G);
                    const int64_t n = rhe((mk(fg, G) * sv + mk(G - fg, G) * fog[c]) * Q{G, 1});
                    want = fromFloat(float(n) / float(G));  // the grid value as float32
                }
                INFO(ps11::precisionName(p) << " lane " << i << " c " << c);
                CHECK(fromFloat(floatAt(img, uint32_t(i), 0, c)) == want);
            }
    }
}
