// The output merger's states (emu/output_merger.*, docs/output-merger.md): MergeState::from
// reads the render states, writesNothing, a null live mask and z, and random states through the
// whole pipeline against a per-pixel model written from output_merger_model.h.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

#include "emu/output_merger.h"
#include "output_merger_model.h"

using namespace emu;
using ps11::Precision;

using namespace mergermodel;

// ---- states -----------------------------------------------------------------------------------

TEST_CASE("merger: MergeState::from reads the render states", "[merger]") {
    DeviceState ds;
    MergeState d = MergeState::from(ds, true, Precision::Fx8);
    // D3D9 defaults: ZENABLE FALSE, no blending, no alpha test, mask 0xf.
    CHECK_FALSE(d.depthTest);
    CHECK_FALSE(d.depthWrite);
    CHECK_FALSE(d.blend);
    CHECK_FALSE(d.alphaTest);
    CHECK(d.colorWrite == 0xfu);
    CHECK(d.depthFunc == D3DCMP_LESSEQUAL);
    ds.renderStates[D3DRS_ZENABLE] = D3DZB_TRUE;
    ds.renderStates[D3DRS_ZFUNC] = D3DCMP_GREATER;
    ds.renderStates[D3DRS_ALPHATESTENABLE] = 1;
    ds.renderStates[D3DRS_ALPHAREF] = 0x1ff;
    ds.renderStates[D3DRS_ALPHAFUNC] = D3DCMP_NOTEQUAL;
    ds.renderStates[D3DRS_FOGENABLE] = 1;
    ds.renderStates[D3DRS_FOGCOLOR] = 0x123456;
    ds.renderStates[D3DRS_ALPHABLENDENABLE] = 1;
    ds.renderStates[D3DRS_SRCBLEND] = D3DBLEND_DESTCOLOR;
    ds.renderStates[D3DRS_DESTBLEND] = D3DBLEND_BLENDFACTOR;
    ds.renderStates[D3DRS_BLENDOP] = D3DBLENDOP_MAX;
    ds.renderStates[D3DRS_SEPARATEALPHABLENDENABLE] = 1;
    ds.renderStates[D3DRS_SRCBLENDALPHA] = D3DBLEND_SRCALPHASAT;
    ds.renderStates[D3DRS_DESTBLENDALPHA] = D3DBLEND_INVDESTALPHA;
    ds.renderStates[D3DRS_BLENDOPALPHA] = D3DBLENDOP_REVSUBTRACT;
    ds.renderStates[D3DRS_BLENDFACTOR] = 0x11223344;
    ds.renderStates[D3DRS_COLORWRITEENABLE] = 0x5;
    MergeState m = MergeState::from(ds, true, Precision::Fx12);
    CHECK(m.depthTest);
    CHECK(m.depthWrite);  // ZWRITEENABLE defaults to TRUE
    CHECK(m.depthFunc == D3DCMP_GREATER);
    CHECK(m.alphaTest);
    CHECK(m.alphaRef == 0xffu);
    CHECK(m.alphaFunc == D3DCMP_NOTEQUAL);
    CHECK(m.fog);
    CHECK(m.fogColor == 0x123456u);
    CHECK(m.blend);
    CHECK(m.srcBlend == D3DBLEND_DESTCOLOR);
    CHECK(m.dstBlend == D3DBLEND_BLENDFACTOR);
    CHECK(m.blendOp == D3DBLENDOP_MAX);
    CHECK(m.separateAlpha);
    CHECK(m.srcBlendAlpha == D3DBLEND_SRCALPHASAT);
    CHECK(m.dstBlendAlpha == D3DBLEND_INVDESTALPHA);
    CHECK(m.blendOpAlpha == D3DBLENDOP_REVSUBTRACT);
    CHECK(m.blendFactor == 0x11223344u);
    CHECK(m.colorWrite == 0x5u);
    CHECK(m.precision == Precision::Fx12);
    // No depth surface: no depth test or write. ZWRITEENABLE without ZENABLE writes nothing.
    CHECK_FALSE(MergeState::from(ds, false, Precision::Fx8).depthTest);
    ds.renderStates[D3DRS_ZENABLE] = D3DZB_FALSE;
    CHECK_FALSE(MergeState::from(ds, true, Precision::Fx8).depthWrite);
    // Table fog is not vertex fog.
    ds.renderStates[D3DRS_FOGTABLEMODE] = D3DFOG_LINEAR;
    CHECK_FALSE(MergeState::from(ds, true, Precision::Fx8).fog);
    // Unknown values act as the state's default and are reported by mergeStateError.
    CHECK_FALSE(mergeStateError(ds));
    ds.renderStates[D3DRS_SRCBLEND] = 99;
    ds.renderStates[D3DRS_BLENDOP] = 0;
    ds.renderStates[D3DRS_ALPHAFUNC] = 9;
    m = MergeState::from(ds, true, Precision::Fx8);
    CHECK(m.srcBlend == D3DBLEND_ONE);
    CHECK(m.blendOp == D3DBLENDOP_ADD);
    CHECK(m.alphaFunc == D3DCMP_ALWAYS);
    const std::optional<CallError> e = mergeStateError(ds);
    REQUIRE(e);
    CHECK(e->hr == D3DERR_INVALIDCALL);
    CHECK(e->code == "E4160");
    CHECK(e->message == "D3DRS_ALPHAFUNC 9 is not a D3DCMPFUNC value");
    ds.renderStates[D3DRS_ALPHAFUNC] = D3DCMP_LESS;
    REQUIRE(mergeStateError(ds));
    CHECK(mergeStateError(ds)->message == "D3DRS_SRCBLEND 99 is not a D3DBLEND value");
}

TEST_CASE("merger: writesNothing only when no pixel can change the target", "[merger]") {
    MergeState st;
    CHECK_FALSE(st.writesNothing());
    st.colorWrite = 0;
    CHECK(st.writesNothing());
    st.depthTest = true, st.depthWrite = true;
    CHECK_FALSE(st.writesNothing());
    st.depthFunc = D3DCMP_NEVER;
    CHECK(st.writesNothing());
    st = MergeState{};
    st.alphaTest = true, st.alphaFunc = D3DCMP_NEVER;
    CHECK(st.writesNothing());
    // Blending 0 * src + 1 * dst (ADD or REVSUBTRACT) keeps every channel.
    st = blendState(D3DBLEND_ZERO, D3DBLEND_ONE, D3DBLENDOP_ADD, Precision::Fx8);
    CHECK(st.writesNothing());
    st.blendOp = D3DBLENDOP_REVSUBTRACT;
    CHECK(st.writesNothing());
    st.blendOp = D3DBLENDOP_SUBTRACT;  // 0 - dst clamps to 0: changes the target
    CHECK_FALSE(st.writesNothing());
    st.blendOp = D3DBLENDOP_MAX;
    CHECK_FALSE(st.writesNothing());
    st.blendOp = D3DBLENDOP_ADD;
    st.separateAlpha = true, st.srcBlendAlpha = D3DBLEND_ONE;  // alpha changes
    CHECK_FALSE(st.writesNothing());
    st.colorWrite = 0x7;  // ... but alpha is masked
    CHECK(st.writesNothing());
    // And the claim holds: such a draw leaves an ideal-profile float target bit-identical,
    // infinities and negative zero included.
    st = blendState(D3DBLEND_ZERO, D3DBLEND_ONE, D3DBLENDOP_ADD, Precision::Ideal);
    Image img = makeImage(D3DFMT_A32B32G32R32F, 16, 1);
    const float d[4] = {-0.0f, INFINITY, 0.5f, -3.0f};
    std::memcpy(img.texel(0, 0), d, 16);
    const std::vector<uint8_t> before(img.bytes.begin(), img.bytes.end());
    Span span(1);
    span.setColor(0, {INFINITY, NAN, -INFINITY, 1.0f});
    run(st, span, &img);
    CHECK(std::vector<uint8_t>(img.bytes.begin(), img.bytes.end()) == before);
}

TEST_CASE("merger: null live means every lane; null z reads 0", "[merger]") {
    Image img = makeImage(D3DFMT_A8R8G8B8, 16, 1);
    Image depth = makeImage(D3DFMT_D16, 16, 1);
    for (uint32_t x = 0; x < 16; ++x) {
        const uint16_t w = 100;
        std::memcpy(depth.texel(x, 0), &w, 2);
    }
    Span span(16);
    for (int i = 0; i < 16; ++i) span.setGrid(i, {i, 2 * i, 3 * i, 255}, Precision::Fx8);
    MergeInputs in = span.inputs(true);
    in.live = nullptr;
    in.z = nullptr;
    MergeState st;
    st.depthTest = true, st.depthWrite = true, st.depthFunc = D3DCMP_LESS;
    MergeStats stats;
    mergePixels(st, in, MergeTarget{&img, &depth}, &stats);
    CHECK(stats.written == 16);
    for (uint32_t x = 0; x < 16; ++x) {
        CHECK(rgbaAt(img, x, 0) == std::array<uint32_t, 4>{x, 2 * x, 3 * x, 255});
        CHECK(depthWord(depth, x) == 0u);
    }
}

TEST_CASE("merger: random states through the whole pipeline match a per-pixel model", "[merger]") {
    // Fog, alpha test, depth test/write, blending (separate alpha too) and write masks drawn at
    // random, in fx8 and fx12 on A8R8G8B8 / X8R8G8B8 with D16 depth; every pixel is predicted by
    // the formulas above, stage by stage, in D3D9's order.
    std::mt19937 rng(2024);
    for (int round = 0; round < 400; ++round) {
        const Precision p = round % 2 ? Precision::Fx12 : Precision::Fx8;
        const int32_t G = ps11::gridScale(p);
        const D3DFORMAT fmt = (round / 2) % 3 == 0 ? D3DFMT_X8R8G8B8 : D3DFMT_A8R8G8B8;
        const bool x8 = fmt == D3DFMT_X8R8G8B8;
        MergeState st;
        st.precision = p;
        st.fog = rng() % 2;
        st.fogColor = rng();
        st.alphaTest = rng() % 2;
        st.alphaFunc = kAllCmps[rng() % 8];
        st.alphaRef = rng() % 256;
        st.depthTest = rng() % 3 != 0;
        st.depthWrite = st.depthTest && rng() % 2;
        st.depthFunc = kAllCmps[rng() % 8];
        st.blend = rng() % 4 != 0;
        st.srcBlend = kAllBlends[rng() % 15], st.dstBlend = kAllBlends[rng() % 15];
        st.blendOp = kAllOps[rng() % 5];
        st.separateAlpha = rng() % 2;
        st.srcBlendAlpha = kAllBlends[rng() % 15], st.dstBlendAlpha = kAllBlends[rng() % 15];
        st.blendOpAlpha = kAllOps[rng() % 5];
        st.blendFactor = rng();
        st.colorWrite = rng() % 3 == 0 ? rng() % 16 : 0xf;
        Image color = makeImage(fmt, 16, 16);
        Image depth = makeImage(D3DFMT_D16, 16, 16);
        Span span(256);
        std::vector<std::array<uint32_t, 4>> dst(256);
        std::vector<uint16_t> dz(256);
        for (int i = 0; i < 256; ++i) {
            std::array<int32_t, 4> n;
            for (int c = 0; c < 4; ++c) n[size_t(c)] = int32_t(rng() % (G + 41u)) - 20;
            span.setGrid(i, n, p);
            span.live[size_t(i)] = rng() % 8 != 0;
            span.fog[size_t(i)] = float(int(rng() % 1200) - 100) / 1000.0f;
            span.z[size_t(i)] = float(rng() % 64) / 63.0f;
            for (int c = 0; c < 4; ++c) dst[size_t(i)][size_t(c)] = rng() % 256;
            setRgba(color, uint32_t(i % 16), uint32_t(i / 16), dst[size_t(i)]);
            dz[size_t(i)] = uint16_t(depthCodeRef(float(rng() % 64) / 63.0f, 16));
            std::memcpy(depth.texel(uint32_t(i % 16), uint32_t(i / 16)), &dz[size_t(i)], 2);
        }
        const MergeStats stats = run(st, span, &color, &depth);
        // The rgb pair the blend leaves as is (ZERO, ONE with ADD or REVSUBTRACT) is not written:
        // it matters only for X8R8G8B8's X byte.
        D3DBLEND rs = st.srcBlend, rd = st.dstBlend;
        pairRef(rs, rd);
        const bool rgbKept = st.blend && rs == D3DBLEND_ZERO && rd == D3DBLEND_ONE &&
                             (st.blendOp == D3DBLENDOP_ADD || st.blendOp == D3DBLENDOP_REVSUBTRACT);
        uint64_t written = 0, aRej = 0, zRej = 0;
        for (int i = 0; i < 256; ++i) {
            const uint32_t x = uint32_t(i % 16), y = uint32_t(i / 16);
            std::array<uint32_t, 4> want = dst[size_t(i)];
            uint16_t wantZ = dz[size_t(i)];
            if (span.live[size_t(i)]) {
                Q s[4];
                int32_t n[4];
                for (int c = 0; c < 4; ++c) n[c] = std::clamp(span.grid[c][size_t(i)], 0, G);
                if (st.fog) {
                    const float f = std::clamp(span.fog[size_t(i)], 0.0f, 1.0f);
                    const int64_t fg = rhe(fromFloat(f) * Q{G, 1});
                    for (int c = 0; c < 3; ++c) {
                        const Q fogc = mk((st.fogColor >> (16 - 8 * c)) & 255, 255);
                        n[c] = int32_t(rhe((mk(fg, G) * mk(n[c], G) + mk(G - fg, G) * fogc) * Q{G, 1}));
                    }
                }
                for (int c = 0; c < 4; ++c) s[c] = mk(n[c], G);
                const uint32_t alpha8 = byteOfQ(s[3]);
                const uint64_t code = depthCodeRef(span.z[size_t(i)], 16);
                if (st.alphaTest && !cmpRef(st.alphaFunc, alpha8, st.alphaRef)) {
                    ++aRej;
                } else if (st.depthTest && !cmpRef(st.depthFunc, code, uint64_t(dz[size_t(i)]))) {
                    ++zRej;
                } else {
                    ++written;
                    if (st.depthWrite) wantZ = uint16_t(code);
                    std::array<uint32_t, 4> v;
                    if (st.blend) {
                        Q d[4];
                        for (int c = 0; c < 4; ++c) d[c] = mk(dst[size_t(i)][size_t(c)], 255);
                        if (x8) d[3] = kOneQ;
                        const std::array<Q, 4> r = blendRef(st, s, d);
                        for (int c = 0; c < 4; ++c) v[size_t(c)] = byteOfQ(r[size_t(c)]);
                    } else {
                        for (int c = 0; c < 4; ++c) v[size_t(c)] = byteOfQ(s[c]);
                    }
                    for (int c = 0; c < 3; ++c)
                        if (st.colorWrite >> c & 1u) want[size_t(c)] = v[size_t(c)];
                    if (x8) {
                        if ((st.colorWrite & 7u) && !rgbKept) want[3] = 255;
                    } else if (st.colorWrite & 8u) {
                        want[3] = v[3];
                    }
                }
            }
            uint16_t gotZ;
            std::memcpy(&gotZ, depth.texel(x, y), 2);
            INFO("round " << round << " lane " << i);
            REQUIRE(rgbaAt(color, x, y) == want);
            REQUIRE(gotZ == wantZ);
        }
        CHECK(stats.written == written);
        CHECK(stats.alphaRejected == aRej);
        CHECK(stats.depthRejected == zRej);
    }
}
