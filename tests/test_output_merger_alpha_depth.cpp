// The output merger's per-pixel tests (emu/output_merger.*, docs/output-merger.md): the alpha test
// with every compare function on 8-bit and float targets, the depth test in every depth format
// (ties, clamping, what Device::Clear stored), and the pipeline's order, live mask and
// statistics, against the exact model of output_merger_model.h.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstring>

#include "emu/device.h"
#include "emu/output_merger.h"
#include "output_merger_model.h"

using namespace emu;
using ps11::Precision;

using namespace mergermodel;

// ---- alpha test -----------------------------------------------------------------------------

TEST_CASE("merger: alpha test with every compare function at the boundary", "[merger]") {
    for (Precision p : {Precision::Fx8, Precision::Fx12, Precision::Float, Precision::Ideal})
        for (D3DCMPFUNC f : kAllCmps)
            for (uint32_t ref : {0u, 1u, 128u, 254u, 255u}) {
                MergeState st;
                st.precision = p;
                st.alphaTest = true, st.alphaFunc = f, st.alphaRef = ref;
                const int32_t G = ps11::gridScale(p);
                Image img = makeImage(D3DFMT_A8R8G8B8, 16, 1);
                Span span(3);
                // Alphas whose 8-bit value is ref - 1, ref, ref + 1 (clamped to 0..255).
                uint32_t alpha8[3];
                for (int i = 0; i < 3; ++i) {
                    const int64_t a = std::clamp<int64_t>(int64_t(ref) - 1 + i, 0, 255);
                    alpha8[i] = uint32_t(a);
                    if (ps11::isFixedPoint(p)) {
                        // fx12: n = 16a + 7 stores round(a + 7/16) = a.
                        span.setGrid(i, {G, G, G, int32_t(a * (G / 255) + (G == 255 ? 0 : 7))}, p);
                    } else {
                        span.setColor(i, {1.0f, 1.0f, 1.0f, float((double(a) + 0.25) / 255.0)});
                    }
                }
                const MergeStats stats = run(st, span, &img);
                uint64_t passed = 0;
                for (int i = 0; i < 3; ++i) {
                    const bool want = cmpRef(f, alpha8[i], ref);
                    passed += want;
                    INFO("profile " << ps11::precisionName(p) << " func " << int(f) << " ref " << ref << " alpha "
                                    << alpha8[i]);
                    CHECK((rgbaAt(img, uint32_t(i), 0)[0] == 255) == want);
                }
                CHECK(stats.written == passed);
                CHECK(stats.alphaRejected == 3 - passed);
            }
}

TEST_CASE("merger: alpha test on float targets compares the value with ALPHAREF / 255 exactly", "[merger]") {
    Image img = makeImage(D3DFMT_A32B32G32R32F, 16, 1);
    MergeState st;
    st.precision = Precision::Float;
    st.alphaTest = true, st.alphaFunc = D3DCMP_GREATEREQUAL, st.alphaRef = 128;
    Span span(3);
    span.setColor(0, {1, 1, 1, 0.5f});             // 0.5 < 128/255: rejected (an 8-bit target would store 128)
    span.setColor(1, {1, 1, 1, 128.0f / 255.0f});  // float(128/255) vs 128/255: compare exactly
    span.setColor(2, {1, 1, 1, 2.0f});
    const MergeStats stats = run(st, span, &img);
    CHECK(floatAt(img, 0, 0, 0) == 0.0f);
    const bool want1 = !(fromFloat(128.0f / 255.0f) < mk(128, 255));
    CHECK((floatAt(img, 1, 0, 0) == 1.0f) == want1);
    CHECK(floatAt(img, 2, 0, 0) == 1.0f);
    CHECK(stats.alphaRejected == (want1 ? 1u : 2u));
    // fx12 on a float target: n / 4080 against ref / 255 in integers: 2048 / 4080 >= 128 / 255.
    st.precision = Precision::Fx12;
    Image img2 = makeImage(D3DFMT_A32B32G32R32F, 16, 1);
    Span s2(2);
    s2.setGrid(0, {4080, 4080, 4080, 2047}, Precision::Fx12);
    s2.setGrid(1, {4080, 4080, 4080, 2048}, Precision::Fx12);
    run(st, s2, &img2);
    CHECK(floatAt(img2, 0, 0, 0) == 0.0f);
    CHECK(floatAt(img2, 1, 0, 0) == 1.0f);
}

// ---- depth ----------------------------------------------------------------------------------

namespace {

void setDepth(Image& img, uint32_t x, D3DFORMAT f, float z, uint32_t stencil = 0) {
    uint8_t* p = img.texel(x, 0);
    if (f == D3DFMT_D16 || f == D3DFMT_D16_LOCKABLE) {
        const uint16_t w = uint16_t(depthCodeRef(z, 16));
        std::memcpy(p, &w, 2);
    } else if (f == D3DFMT_D24S8 || f == D3DFMT_D24X8) {
        const uint32_t w = uint32_t(depthCodeRef(z, 24) << 8) | stencil;
        std::memcpy(p, &w, 4);
    } else if (f == D3DFMT_D32) {
        const uint32_t w = uint32_t(depthCodeRef(z, 32));
        std::memcpy(p, &w, 4);
    } else {
        std::memcpy(p, &z, 4);
    }
}

}  // namespace

TEST_CASE("merger: depth test with every compare function, write on and off, every depth format", "[merger]") {
    const D3DFORMAT formats[] = {D3DFMT_D16,   D3DFMT_D16_LOCKABLE, D3DFMT_D24S8,
                                 D3DFMT_D24X8, D3DFMT_D32,          D3DFMT_D32F_LOCKABLE};
    for (D3DFORMAT fmt : formats)
        for (D3DCMPFUNC f : kAllCmps)
            for (bool write : {false, true}) {
                MergeState st;
                st.depthTest = true, st.depthWrite = write, st.depthFunc = f;
                Image color = makeImage(D3DFMT_A8R8G8B8, 16, 1);
                Image depth = makeImage(fmt, 16, 1);
                const int bits = int(depth.format->depthBits);
                const bool isFloat = fmt == D3DFMT_D32F_LOCKABLE;
                // Stored 0.5; incoming less, equal, greater by one step, and a z that quantises to
                // the same code (equal for integer formats).
                const float stored = 0.5f;
                const float step =
                    isFloat ? std::nextafter(0.5f, 1.0f) - 0.5f : float(1.0 / double((uint64_t(1) << bits) - 1));
                float zs[4] = {stored - step, stored, stored + step, std::nextafter(stored, 1.0f)};
                // D32: a float z cannot resolve 2^-32; Clear's z * (2^32 - 1) in double is exact for
                // z of at most 21 significant bits, which these are.
                if (bits == 32 && !isFloat) zs[0] = 0.25f, zs[2] = 0.75f, zs[3] = 0.5f + 0x1p-20f;
                Span span(4);
                for (int i = 0; i < 4; ++i) {
                    setDepth(depth, uint32_t(i), fmt, stored, 0xa5);
                    span.setGrid(i, {255, 255, 255, 255}, Precision::Fx8);
                    span.z[size_t(i)] = zs[i];
                }
                std::vector<uint32_t> before(4);
                for (uint32_t i = 0; i < 4; ++i) before[i] = depthWord(depth, i);
                const MergeStats stats = run(st, span, &color, &depth);
                uint64_t passed = 0;
                for (int i = 0; i < 4; ++i) {
                    bool want;
                    uint32_t code = 0;
                    if (isFloat) {
                        want = cmpRef(f, zs[i], stored);
                        std::memcpy(&code, &zs[i], 4);
                    } else {
                        const uint64_t in = depthCodeRef(zs[i], bits), old = depthCodeRef(stored, bits);
                        want = cmpRef(f, in, old);
                        code = bits == 24
                                   ? uint32_t(in << 8) | (fmt == D3DFMT_D24S8 || fmt == D3DFMT_D24X8 ? 0xa5u : 0u)
                                   : uint32_t(in);
                    }
                    passed += want;
                    INFO(formatName(fmt) << " func " << int(f) << " write " << write << " lane " << i);
                    CHECK((rgbaAt(color, uint32_t(i), 0)[0] == 255) == want);
                    CHECK(depthWord(depth, uint32_t(i)) == (want && write ? code : before[size_t(i)]));
                }
                CHECK(stats.written == passed);
                CHECK(stats.depthRejected == 4 - passed);
            }
}

TEST_CASE("merger: depth ties round to even like Clear, and z is clamped to [0, 1]", "[merger]") {
    // 0.5 * (2^bits - 1) is an exact tie: 32767.5 -> 32768, 8388607.5 -> 8388608, 2147483647.5 -> 2^31.
    const struct {
        D3DFORMAT f;
        uint32_t want;
    } cases[] = {{D3DFMT_D16, 32768u}, {D3DFMT_D24X8, 8388608u << 8}, {D3DFMT_D32, 2147483648u}};
    for (const auto& c : cases) {
        MergeState st;
        st.depthTest = true, st.depthWrite = true, st.depthFunc = D3DCMP_ALWAYS;
        Image depth = makeImage(c.f, 16, 1);
        Span span(3);
        span.z = {0.5f, -2.0f, 7.0f};
        run(st, span, nullptr, &depth);
        CHECK(depthWord(depth, 0) == c.want);
        CHECK(depthWord(depth, 1) == 0u);
        const uint32_t one = c.f == D3DFMT_D16 ? 0xffffu : c.f == D3DFMT_D24X8 ? 0xffffff00u : 0xffffffffu;
        CHECK(depthWord(depth, 2) == one);
    }
}

TEST_CASE("merger: depth compares against what Device::Clear stored", "[merger]") {
    for (D3DFORMAT fmt : {D3DFMT_D16_LOCKABLE, D3DFMT_D32F_LOCKABLE})
        for (float z : {0.0f, 0.3f, 0.5f, 0.7071f, 1.0f}) {
            Device dev;
            Handle ds;
            REQUIRE(dev.CreateDepthStencilSurface(16, 1, fmt, &ds) == D3D_OK);
            REQUIRE(dev.SetDepthStencilSurface(ds) == D3D_OK);
            REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_ZBUFFER, 0, z, 0) == D3D_OK);
            D3DLOCKED_RECT lr{};
            REQUIRE(dev.LockRect(ds, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
            Image depth = makeImage(fmt, 16, 1);
            std::memcpy(depth.bytes.data(), lr.pBits, depth.bytes.size());
            REQUIRE(dev.UnlockRect(ds) == D3D_OK);
            MergeState st;
            st.depthTest = true, st.depthWrite = false, st.depthFunc = D3DCMP_EQUAL;
            Span span(1);
            span.z[0] = z;
            const MergeStats stats = run(st, span, nullptr, &depth);
            INFO(formatName(fmt) << " z " << z);
            CHECK(stats.written == 1);
            CHECK(stats.depthRejected == 0);
        }
}

TEST_CASE("merger: pipeline order, live mask and statistics", "[merger]") {
    MergeState st;
    st.alphaTest = true, st.alphaFunc = D3DCMP_GREATER, st.alphaRef = 100;
    st.depthTest = true, st.depthWrite = true, st.depthFunc = D3DCMP_LESS;
    Image color = makeImage(D3DFMT_A8R8G8B8, 16, 16);
    Image depth = makeImage(D3DFMT_D16, 16, 16);
    for (uint32_t y = 0; y < 16; ++y)
        for (uint32_t x = 0; x < 16; ++x) {
            const uint16_t w = 32768;
            std::memcpy(depth.texel(x, y), &w, 2);
        }
    Span span(256);
    uint64_t live = 0, alphaRej = 0, depthRej = 0, written = 0;
    for (int i = 0; i < 256; ++i) {
        const int32_t a = (i * 37) % 256;
        span.setGrid(i, {1, 2, 3, a}, Precision::Fx8);
        span.z[size_t(i)] = (i % 3 == 0) ? 0.75f : 0.25f;  // 0.75 fails LESS against 0.5
        span.live[size_t(i)] = (i % 5 != 0);               // killed / uncovered lanes
        if (!span.live[size_t(i)]) continue;
        ++live;
        if (!(a > 100))
            ++alphaRej;
        else if (i % 3 == 0)
            ++depthRej;
        else
            ++written;
    }
    const MergeStats stats = run(st, span, &color, &depth);
    CHECK(stats.alphaRejected == alphaRej);
    CHECK(stats.depthRejected == depthRej);
    CHECK(stats.written == written);
    CHECK(alphaRej + depthRej + written == live);
    for (int i = 0; i < 256; ++i) {
        const uint32_t x = uint32_t(i % 16), y = uint32_t(i / 16);
        uint16_t dw;
        std::memcpy(&dw, depth.texel(x, y), 2);
        const bool shouldWrite = span.live[size_t(i)] && span.grid[3][size_t(i)] > 100 && i % 3 != 0;
        INFO("lane " << i);
        // Alpha-rejected, depth-rejected and dead lanes write neither colour nor depth.
        CHECK(dw == (shouldWrite ? uint16_t(depthCodeRef(0.25f, 16)) : 32768));
        CHECK(rgbaAt(color, x, y) == (shouldWrite ? std::array<uint32_t, 4>{1, 2, 3, uint32_t(span.grid[3][size_t(i)])}
                                                  : std::array<uint32_t, 4>{0, 0, 0, 0}));
    }
    // Statistics add up across calls.
    MergeStats total;
    mergePixels(MergeState{}, span.inputs(true), MergeTarget{&color, nullptr}, &total);
    mergePixels(MergeState{}, span.inputs(true), MergeTarget{&color, nullptr}, &total);
    CHECK(total.written == 2 * live);
    CHECK(total.alphaRejected == 0);
}
