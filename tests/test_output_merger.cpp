// The output merger (emu/output_merger.*, docs/output-merger.md): blending into 8-bit targets,
// every factor and op in fx8, fx12, float and ideal, row runs, separate alpha. Every expected value
// is derived here from the D3D9 formulas with exact rational arithmetic (fractions of 128-bit
// integers) and a half-even rounding written in output_merger_model.h — never taken from the
// merger. Stores without blending, write masks and fog are tested in
// test_output_merger_stores.cpp; the alpha and depth tests and the pipeline's order in
// test_output_merger_alpha_depth.cpp; float targets in test_output_merger_float.cpp; the
// states in test_output_merger_state.cpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <random>
#include <utility>
#include <vector>

#include "emu/output_merger.h"
#include "output_merger_model.h"

using namespace emu;
using ps11::Precision;

using namespace mergermodel;

namespace {

// Runs a blend configuration over 256 pixels with random (and extreme) source grid values and
// destination bytes in an fx profile, and checks every stored byte against the rational model.
// `row`: the lanes are one run of a row (MergeInputs::row, every lane live, as the row paths
// hand them over), pixels 7 … 262 of row 1 of a 300×2 target; else a 16×16 block.
void checkBlendFx(const MergeState& st, D3DFORMAT fmt, uint32_t seed, bool row = false) {
    const int32_t G = ps11::gridScale(st.precision);
    std::mt19937 rng(seed);
    Image img = row ? makeImage(fmt, 300, 2) : makeImage(fmt, 16, 16);
    Span span(256);
    const auto at = [&](int i) {
        return row ? std::pair<uint32_t, uint32_t>(uint32_t(i + 7), 1u)
                   : std::pair<uint32_t, uint32_t>(uint32_t(i % 16), uint32_t(i / 16));
    };
    for (int i = 0; i < 256; ++i) span.x[size_t(i)] = int32_t(at(i).first), span.y[size_t(i)] = int32_t(at(i).second);
    std::vector<std::array<uint32_t, 4>> dst(256);
    const int32_t extremes[] = {0, G, G / 2, 1, G - 1};
    for (int i = 0; i < 256; ++i) {
        std::array<int32_t, 4> n;
        for (int c = 0; c < 4; ++c) {
            // Mostly in [0, G], some outside (the 8-bit target saturates them first).
            const uint32_t r = rng() % 10;
            n[size_t(c)] = r == 0   ? extremes[rng() % 5]
                           : r == 1 ? int32_t(rng() % (3u * G)) - G
                                    : int32_t(rng() % (G + 1u));
        }
        span.setGrid(i, n, st.precision);
        for (int c = 0; c < 4; ++c) dst[size_t(i)][size_t(c)] = (rng() % 7 == 0) ? (rng() % 2) * 255 : rng() % 256;
        setRgba(img, at(i).first, at(i).second, dst[size_t(i)]);
    }
    MergeInputs in = span.inputs(true);
    if (row) in.row = true, in.live = nullptr;
    mergePixels(st, in, MergeTarget{&img, nullptr}, nullptr);
    const bool x8 = fmt == D3DFMT_X8R8G8B8;
    for (int i = 0; i < 256; ++i) {
        Q s[4], d[4];
        for (int c = 0; c < 4; ++c) {
            const int32_t n = std::clamp(span.grid[c][size_t(i)], 0, G);  // saturated for an 8-bit target
            s[c] = mk(n, G);
            d[c] = mk(dst[size_t(i)][size_t(c)], 255);
        }
        if (x8) d[3] = kOneQ;  // X8R8G8B8 reads alpha as 1
        const std::array<Q, 4> r = blendRef(st, s, d);
        const std::array<uint32_t, 4> got = rgbaAt(img, at(i).first, at(i).second);
        for (int c = 0; c < 4; ++c) {
            uint32_t want = byteOfQ(r[size_t(c)]);
            if (x8 && c == 3) want = 255;
            if (!(st.colorWrite >> c & 1u)) want = dst[size_t(i)][size_t(c)];
            INFO("src " << int(st.srcBlend) << " dst " << int(st.dstBlend) << " op " << int(st.blendOp) << " srcA "
                        << int(st.srcBlendAlpha) << " dstA " << int(st.dstBlendAlpha) << " opA " << int(st.blendOpAlpha)
                        << " lane " << i << " channel " << c << " s " << span.grid[c][size_t(i)] << " d "
                        << dst[size_t(i)][size_t(c)]);
            REQUIRE(got[size_t(c)] == want);
        }
    }
}

}  // namespace

// ---- blending -------------------------------------------------------------------------------

TEST_CASE("merger: every D3DBLEND pair with ADD in fx8 matches the exact formula", "[merger]") {
    uint32_t seed = 1;
    for (D3DBLEND s : kAllBlends)
        for (D3DBLEND d : kAllBlends)
            checkBlendFx(blendState(s, d, D3DBLENDOP_ADD, Precision::Fx8), D3DFMT_A8R8G8B8, seed++);
}

TEST_CASE("merger: every blend op with every factor (as source and as destination) in fx8", "[merger]") {
    uint32_t seed = 1000;
    for (D3DBLENDOP op : kAllOps)
        for (D3DBLEND f : kAllBlends) {
            checkBlendFx(blendState(f, D3DBLEND_INVSRCALPHA, op, Precision::Fx8), D3DFMT_A8R8G8B8, seed++);
            checkBlendFx(blendState(D3DBLEND_SRCALPHA, f, op, Precision::Fx8), D3DFMT_A8R8G8B8, seed++);
        }
}

TEST_CASE("merger: separate alpha blending uses its own factors and op for alpha", "[merger]") {
    uint32_t seed = 2000;
    for (D3DBLENDOP opA : kAllOps)
        for (D3DBLEND fa : kAllBlends) {
            MergeState st = blendState(D3DBLEND_SRCALPHA, D3DBLEND_INVSRCALPHA, D3DBLENDOP_ADD, Precision::Fx8);
            st.separateAlpha = true;
            st.srcBlendAlpha = fa, st.dstBlendAlpha = D3DBLEND_DESTCOLOR, st.blendOpAlpha = opA;
            checkBlendFx(st, D3DFMT_A8R8G8B8, seed++);
            st.srcBlendAlpha = D3DBLEND_ONE, st.dstBlendAlpha = fa;
            checkBlendFx(st, D3DFMT_A8R8G8B8, seed++);
        }
    // Without SEPARATEALPHABLENDENABLE the alpha states are ignored.
    MergeState st = blendState(D3DBLEND_DESTCOLOR, D3DBLEND_SRCCOLOR, D3DBLENDOP_SUBTRACT, Precision::Fx8);
    st.srcBlendAlpha = D3DBLEND_ZERO, st.dstBlendAlpha = D3DBLEND_ZERO, st.blendOpAlpha = D3DBLENDOP_MIN;
    checkBlendFx(st, D3DFMT_A8R8G8B8, 77);
}

TEST_CASE("merger: fx12 blending is exact on the 4080 grid and rounds once to 8 bits", "[merger]") {
    uint32_t seed = 3000;
    for (D3DBLENDOP op : kAllOps)
        for (D3DBLEND f : kAllBlends) {
            checkBlendFx(blendState(f, D3DBLEND_DESTALPHA, op, Precision::Fx12), D3DFMT_A8R8G8B8, seed++);
            checkBlendFx(blendState(D3DBLEND_SRCCOLOR, f, op, Precision::Fx12), D3DFMT_A8R8G8B8, seed++);
        }
}

TEST_CASE("merger: fx blending of a row run gives the formula's bytes for every factor pair", "[merger]") {
    // The row paths' spans: words loaded and stored in place; factor pairs of ZERO and ONE take
    // the byte of ±s ± d without products.
    uint32_t seed = 7000;
    for (Precision p : {Precision::Fx8, Precision::Fx12})
        for (D3DBLENDOP op : kAllOps)
            for (D3DBLEND fs : kAllBlends) {
                for (D3DBLEND fd : kAllBlends) checkBlendFx(blendState(fs, fd, op, p), D3DFMT_A8R8G8B8, seed++, true);
                // (X8R8G8B8's X byte becomes 0xff where a channel is written: never with ZERO/ONE ADD.)
                checkBlendFx(blendState(fs, D3DBLEND_INVSRCALPHA, op, p), D3DFMT_X8R8G8B8, seed++, true);
            }
    // The same pairs of ZERO and ONE on a 16×16 block (gathered lanes).
    for (Precision p : {Precision::Fx8, Precision::Fx12})
        for (D3DBLENDOP op : kAllOps)
            for (D3DBLEND fs : {D3DBLEND_ZERO, D3DBLEND_ONE})
                for (D3DBLEND fd : {D3DBLEND_ZERO, D3DBLEND_ONE})
                    checkBlendFx(blendState(fs, fd, op, p), D3DFMT_A8R8G8B8, seed++);
}

TEST_CASE("merger: blending behind a passing alpha or depth test gives the same bytes", "[merger]") {
    // Fog, alpha test and depth test take the general per-pixel loop; blending there must agree
    // with the formula too (an ALWAYS test changes nothing).
    uint32_t seed = 5000;
    for (Precision p : {Precision::Fx8, Precision::Fx12})
        for (D3DBLENDOP op : kAllOps)
            for (D3DBLEND f : kAllBlends) {
                MergeState st = blendState(f, D3DBLEND_INVSRCCOLOR, op, p);
                st.alphaTest = true, st.alphaFunc = D3DCMP_ALWAYS;
                st.separateAlpha = true, st.srcBlendAlpha = D3DBLEND_DESTALPHA, st.dstBlendAlpha = f;
                st.blendOpAlpha = D3DBLENDOP_REVSUBTRACT;
                checkBlendFx(st, seed % 2 ? D3DFMT_X8R8G8B8 : D3DFMT_A8R8G8B8, seed);
                ++seed;
            }
}

TEST_CASE("merger: X8R8G8B8 reads destination alpha as 1 and stores X = 0xff", "[merger]") {
    uint32_t seed = 4000;
    checkBlendFx(blendState(D3DBLEND_ONE, D3DBLEND_ONE, D3DBLENDOP_ADD, Precision::Fx8), D3DFMT_X8R8G8B8, seed++);
    for (D3DBLEND f : {D3DBLEND_DESTALPHA, D3DBLEND_INVDESTALPHA, D3DBLEND_SRCALPHASAT, D3DBLEND_DESTCOLOR}) {
        checkBlendFx(blendState(D3DBLEND_ONE, f, D3DBLENDOP_ADD, Precision::Fx8), D3DFMT_X8R8G8B8, seed++);
        checkBlendFx(blendState(f, D3DBLEND_ONE, D3DBLENDOP_ADD, Precision::Fx12), D3DFMT_X8R8G8B8, seed++);
    }
    // No blending, alpha masked off: X still becomes 0xff with the colour.
    Image img = makeImage(D3DFMT_X8R8G8B8, 16, 1);
    Span span(1);
    span.setGrid(0, {10, 20, 30, 0}, Precision::Fx8);
    MergeState st;
    st.colorWrite = 0x7;
    run(st, span, &img);
    CHECK(img.texel(0, 0)[3] == 0xff);
    CHECK(rgbaAt(img, 0, 0)[0] == 10);
    // Only alpha enabled: an X8R8G8B8 texel does not change at all.
    img.texel(1, 0)[3] = 0x12;
    Span one(2);
    one.setGrid(1, {1, 2, 3, 4}, Precision::Fx8);
    one.live[0] = 0;
    st.colorWrite = 0x8;
    run(st, one, &img);
    CHECK(rgbaAt(img, 1, 0) == std::array<uint32_t, 4>{0, 0, 0, 0x12});
}

TEST_CASE("merger: fixed-point blend ties and the documented arithmetic", "[merger]") {
    Image img = makeImage(D3DFMT_A8R8G8B8, 16, 1);
    Span span(4);
    // fx12: s = 8/4080 (half of an 8-bit step) with ONE/ZERO: 8/16 = 0.5 -> 0 (even); 24 -> 2.
    MergeState st = blendState(D3DBLEND_ONE, D3DBLEND_ZERO, D3DBLENDOP_ADD, Precision::Fx12);
    span.setGrid(0, {8, 24, 40, 4080}, Precision::Fx12);
    span.setGrid(1, {4088, -5, 2040, 2056}, Precision::Fx12);  // saturated 4080 -> 255; 2040 -> 127.5 -> 128
    run(st, span, &img);
    CHECK(rgbaAt(img, 0, 0) == std::array<uint32_t, 4>{0, 2, 2, 255});
    CHECK(rgbaAt(img, 1, 0) == std::array<uint32_t, 4>{255, 0, 128, 128});  // 2056/16 = 128.5 -> 128
    // fx8 SRCALPHA/INVSRCALPHA: 200 * 100 + 55 * 40 = 22200; 22200 / 255 = 87.06 -> 87.
    Image img8 = makeImage(D3DFMT_A8R8G8B8, 16, 1);
    setRgba(img8, 0, 0, {40, 40, 40, 40});
    Span s8(1);
    s8.setGrid(0, {100, 100, 100, 200}, Precision::Fx8);
    run(blendState(D3DBLEND_SRCALPHA, D3DBLEND_INVSRCALPHA, D3DBLENDOP_ADD, Precision::Fx8), s8, &img8);
    // alpha: 200 * 200 + 55 * 40 = 42200; / 255 = 165.49 -> 165.
    CHECK(rgbaAt(img8, 0, 0) == std::array<uint32_t, 4>{87, 87, 87, 165});
}

TEST_CASE("merger: float and ideal profiles blend into 8-bit targets", "[merger]") {
    // Dyadic sources and destinations 0 / 255 keep float32 exact, so the rational model applies.
    for (Precision p : {Precision::Float, Precision::Ideal})
        for (D3DBLENDOP op : kAllOps)
            for (D3DBLEND f : kAllBlends) {
                MergeState st = blendState(f, D3DBLEND_INVSRCALPHA, op, p);
                st.blendFactor = 0xff00ff00u;
                Image img = makeImage(D3DFMT_A8R8G8B8, 16, 16);
                Span span(64);
                std::vector<std::array<uint32_t, 4>> dst(64);
                for (int i = 0; i < 64; ++i) {
                    std::array<float, 4> v;
                    for (int c = 0; c < 4; ++c)
                        v[size_t(c)] = float((i * 7 + c * 3) % 13 - 2) / 8.0f;  // k/8, some outside [0, 1]
                    span.setColor(i, v);
                    for (int c = 0; c < 4; ++c) dst[size_t(i)][size_t(c)] = ((i >> c) & 1) * 255;
                    setRgba(img, uint32_t(i % 16), uint32_t(i / 16), dst[size_t(i)]);
                }
                run(st, span, &img);
                for (int i = 0; i < 64; ++i) {
                    Q s[4], d[4];
                    for (int c = 0; c < 4; ++c) {
                        // The 8-bit target saturates the source before blending.
                        s[c] = qmin(qmax(fromFloat(span.color[c][size_t(i)]), kZeroQ), kOneQ);
                        d[c] = mk(dst[size_t(i)][size_t(c)], 255);
                    }
                    const std::array<Q, 4> r = blendRef(st, s, d);
                    const std::array<uint32_t, 4> got = rgbaAt(img, uint32_t(i % 16), uint32_t(i / 16));
                    for (int c = 0; c < 4; ++c) {
                        INFO("profile " << ps11::precisionName(p) << " op " << int(op) << " f " << int(f) << " lane "
                                        << i << " c " << c);
                        CHECK(got[size_t(c)] == byteOfQ(r[size_t(c)]));
                    }
                }
            }
}

TEST_CASE("merger: float-profile ONE/ONE ADD into 8-bit targets equals the general blend", "[merger]") {
    // The additive path (no fog) against the same blend through the general path (fog on, with
    // fog factor 1: the colour is unchanged), for random colours (NaN, infinities, negatives,
    // values above 1), destination bytes, X8 targets, write masks and span lengths.
    std::mt19937 rng(42);
    const float specials[] = {NAN, INFINITY, -INFINITY, -0.0f, 0.0f, 1.0f, 2.5f, -1.0f, 0.5f / 255, 1e-30f};
    for (int round = 0; round < 40; ++round) {
        const D3DFORMAT fmt = round % 3 ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8;
        const Precision p = round % 2 ? Precision::Float : Precision::Ideal;
        MergeState st = blendState(D3DBLEND_ONE, D3DBLEND_ONE, D3DBLENDOP_ADD, p);
        st.colorWrite = round % 5 == 0 ? DWORD(rng() % 16) : 0xfu;
        const int lanes = 1 + (round * 7) % 64;  // vector blocks and a scalar tail
        Span span(lanes);
        for (int i = 0; i < lanes; ++i) {
            std::array<float, 4> v;
            for (float& f : v) f = rng() % 4 == 0 ? specials[rng() % 10] : float(int(rng() % 3000) - 500) / 1000.0f;
            span.setColor(i, v);
            span.live[size_t(i)] = rng() % 8 != 0;
        }
        Image fast = makeImage(fmt, 16, 4), general = makeImage(fmt, 16, 4);
        for (size_t b = 0; b < fast.bytes.size(); ++b) fast.bytes[b] = general.bytes[b] = uint8_t(rng());
        const MergeStats a = run(st, span, &fast);
        st.fog = true;
        st.fogColor = 0x00808080u;
        const MergeStats b = run(st, span, &general);
        CHECK(a.written == b.written);
        CHECK(std::vector<uint8_t>(fast.bytes.begin(), fast.bytes.end()) ==
              std::vector<uint8_t>(general.bytes.begin(), general.bytes.end()));
    }
}
