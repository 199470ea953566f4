// The output merger (emu/output_merger.*, docs/output-merger.md). Every expected value is
// derived here from the D3D9 formulas with exact rational arithmetic (fractions of 128-bit
// integers) and a half-even rounding written in this file — never taken from the merger.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "emu/device.h"
#include "emu/format.h"
#include "emu/output_merger.h"
#include "emu/resources.h"
#include "simd_levels.h"
#include "ps11/simd_dispatch.h"

using namespace emu;
using ps11::Precision;

namespace {

// ---- exact rationals -------------------------------------------------------------------------
using I = __int128;

I gcd128(I a, I b) {
    if (a < 0) a = -a;
    if (b < 0) b = -b;
    while (b) {
        const I t = a % b;
        a = b, b = t;
    }
    return a;
}

struct Q {
    I n = 0, d = 1;
};
Q mk(I n, I d) {
    if (d < 0) n = -n, d = -d;
    const I g = gcd128(n, d);
    return g > 1 ? Q{n / g, d / g} : Q{n, d};
}
Q operator+(Q a, Q b) { return mk(a.n * b.d + b.n * a.d, a.d * b.d); }
Q operator-(Q a, Q b) { return mk(a.n * b.d - b.n * a.d, a.d * b.d); }
Q operator*(Q a, Q b) { return mk(a.n * b.n, a.d * b.d); }
bool operator<(Q a, Q b) { return a.n * b.d < b.n * a.d; }
bool operator==(Q a, Q b) { return a.n * b.d == b.n * a.d; }
Q qmin(Q a, Q b) { return b < a ? b : a; }
Q qmax(Q a, Q b) { return a < b ? b : a; }
const Q kZeroQ{0, 1}, kOneQ{1, 1};

// round_half_even of an exact rational (floor division, then the tie rule).
int64_t rhe(Q r) {
    I q = r.n / r.d, m = r.n % r.d;
    if (m < 0) m += r.d, q -= 1;
    if (2 * m > r.d || (2 * m == r.d && (q & 1))) ++q;
    return int64_t(q);
}
// An exact float as a rational (every finite float is m * 2^e).
Q fromFloat(float f) {
    int e = 0;
    const double m = std::frexp(double(f), &e);  // f = m * 2^e, |m| in [0.5, 1)
    const I mant = I(std::ldexp(m, 53));         // exact: 53 bits
    e -= 53;
    return e >= 0 ? mk(mant * (I(1) << e), 1) : mk(mant, I(1) << (-e));
}
// The 8-bit store of a real value: saturate, then round_half_even(x * 255).
uint32_t byteOfQ(Q r) {
    if (r < kZeroQ) r = kZeroQ;
    if (kOneQ < r) r = kOneQ;
    return uint32_t(rhe(r * Q{255, 1}));
}

// ---- the D3D9 blend formulas ----------------------------------------------------------------
// Factor per the D3DBLEND reference page: channel c of (r, g, b, a).
Q factorRef(D3DBLEND b, int c, const Q* s, const Q* d, const Q* bf) {
    switch (b) {
        case D3DBLEND_ZERO:
            return kZeroQ;
        case D3DBLEND_ONE:
            return kOneQ;
        case D3DBLEND_SRCCOLOR:
            return s[c];
        case D3DBLEND_INVSRCCOLOR:
            return kOneQ - s[c];
        case D3DBLEND_SRCALPHA:
            return s[3];
        case D3DBLEND_INVSRCALPHA:
            return kOneQ - s[3];
        case D3DBLEND_DESTALPHA:
            return d[3];
        case D3DBLEND_INVDESTALPHA:
            return kOneQ - d[3];
        case D3DBLEND_DESTCOLOR:
            return d[c];
        case D3DBLEND_INVDESTCOLOR:
            return kOneQ - d[c];
        case D3DBLEND_SRCALPHASAT:
            return c == 3 ? kOneQ : qmin(s[3], kOneQ - d[3]);  // (f, f, f, 1)
        case D3DBLEND_BLENDFACTOR:
            return bf[c];
        case D3DBLEND_INVBLENDFACTOR:
            return kOneQ - bf[c];
        default:
            FAIL("factor " << int(b));
            return kZeroQ;
    }
}
// BOTHSRCALPHA / BOTHINVSRCALPHA as the source factor set both factors (D3D9 docs); as a
// destination factor they act as the destination half of their pair (docs/output-merger.md).
void pairRef(D3DBLEND& s, D3DBLEND& d) {
    if (s == D3DBLEND_BOTHSRCALPHA)
        s = D3DBLEND_SRCALPHA, d = D3DBLEND_INVSRCALPHA;
    else if (s == D3DBLEND_BOTHINVSRCALPHA)
        s = D3DBLEND_INVSRCALPHA, d = D3DBLEND_SRCALPHA;
    else if (d == D3DBLEND_BOTHSRCALPHA)
        d = D3DBLEND_INVSRCALPHA;
    else if (d == D3DBLEND_BOTHINVSRCALPHA)
        d = D3DBLEND_SRCALPHA;
}
Q opRef(D3DBLENDOP op, Q s, Q fs, Q d, Q fd) {
    switch (op) {
        case D3DBLENDOP_ADD:
            return s * fs + d * fd;
        case D3DBLENDOP_SUBTRACT:
            return s * fs - d * fd;
        case D3DBLENDOP_REVSUBTRACT:
            return d * fd - s * fs;
        case D3DBLENDOP_MIN:
            return qmin(s, d);  // factors ignored
        case D3DBLENDOP_MAX:
            return qmax(s, d);
        default:
            FAIL("op");
            return kZeroQ;
    }
}
// The blended real value of every channel (before the store's clamp).
std::array<Q, 4> blendRef(const MergeState& st, const Q* s, const Q* d) {
    const Q bf[4] = {mk((st.blendFactor >> 16) & 255, 255), mk((st.blendFactor >> 8) & 255, 255),
                     mk(st.blendFactor & 255, 255), mk(st.blendFactor >> 24, 255)};
    D3DBLEND sc = st.srcBlend, dc = st.dstBlend;
    pairRef(sc, dc);
    D3DBLEND sa = sc, da = dc;
    D3DBLENDOP oa = st.blendOp;
    if (st.separateAlpha) {
        sa = st.srcBlendAlpha, da = st.dstBlendAlpha, oa = st.blendOpAlpha;
        pairRef(sa, da);
    }
    std::array<Q, 4> r;
    for (int c = 0; c < 4; ++c) {
        const D3DBLEND fs = c < 3 ? sc : sa, fd = c < 3 ? dc : da;
        r[size_t(c)] =
            opRef(c < 3 ? st.blendOp : oa, s[c], factorRef(fs, c, s, d, bf), d[c], factorRef(fd, c, s, d, bf));
    }
    return r;
}

// ---- targets and inputs --------------------------------------------------------------------
Image makeImage(D3DFORMAT f, uint32_t w, uint32_t h) {
    Image img;
    img.format = formatInfo(f);
    REQUIRE(img.format);
    img.width = w, img.height = h;
    img.rowPitch = rowPitchOf(*img.format, w);
    img.slicePitch = uint64_t(img.rowPitch) * h;
    img.bytes.assign(size_t(img.slicePitch), 0);
    return img;
}
// r g b a bytes of an 8-bit ARGB texel (memory B G R A).
std::array<uint32_t, 4> rgbaAt(const Image& img, uint32_t x, uint32_t y) {
    const uint8_t* p = img.texel(x, y);
    return {p[2], p[1], p[0], p[3]};
}
void setRgba(Image& img, uint32_t x, uint32_t y, std::array<uint32_t, 4> v) {
    uint8_t* p = img.texel(x, y);
    p[0] = uint8_t(v[2]), p[1] = uint8_t(v[1]), p[2] = uint8_t(v[0]), p[3] = uint8_t(v[3]);
}
float floatAt(const Image& img, uint32_t x, uint32_t y, int c) {
    float f;
    std::memcpy(&f, img.texel(x, y) + 4 * c, 4);
    return f;
}
uint16_t halfAt(const Image& img, uint32_t x, uint32_t y, int c) {
    uint16_t h;
    std::memcpy(&h, img.texel(x, y) + 2 * c, 2);
    return h;
}

// A span of shaded pixels: lane i at (i % 16, i / 16).
struct Span {
    int count = 0;
    std::vector<int32_t> x, y;
    std::vector<uint8_t> live;
    std::vector<int32_t> grid[4];
    std::vector<float> color[4];
    std::vector<float> fog, z;
    explicit Span(int n)
        : count(n), x(size_t(n)), y(size_t(n)), live(size_t(n), 1), fog(size_t(n), 1.0f), z(size_t(n), 0.5f) {
        for (int i = 0; i < n; ++i) x[size_t(i)] = i % 16, y[size_t(i)] = i / 16;
        for (int c = 0; c < 4; ++c) grid[c].assign(size_t(n), 0), color[c].assign(size_t(n), 0.0f);
    }
    // Sets lane i's r0 in a profile: grid integers (fx) and their real values.
    void setGrid(int i, std::array<int32_t, 4> n, Precision p) {
        const int32_t G = ps11::gridScale(p);
        for (int c = 0; c < 4; ++c) {
            grid[c][size_t(i)] = n[size_t(c)];
            color[c][size_t(i)] = float(n[size_t(c)]) / float(G);
        }
    }
    void setColor(int i, std::array<float, 4> v) {
        for (int c = 0; c < 4; ++c) color[c][size_t(i)] = v[size_t(c)];
    }
    MergeInputs inputs(bool withGrid) const {
        MergeInputs in;
        in.count = count;
        in.x = x.data(), in.y = y.data(), in.live = live.data();
        for (int c = 0; c < 4; ++c) {
            in.color[c] = color[c].data();
            in.grid[c] = withGrid ? grid[c].data() : nullptr;
        }
        in.fog = fog.data(), in.z = z.data();
        return in;
    }
};

MergeStats run(const MergeState& st, const Span& span, Image* color, Image* depth = nullptr) {
    MergeStats stats;
    mergePixels(st, span.inputs(ps11::isFixedPoint(st.precision)), MergeTarget{color, depth}, &stats);
    return stats;
}

const D3DBLEND kAllBlends[] = {D3DBLEND_ZERO,
                               D3DBLEND_ONE,
                               D3DBLEND_SRCCOLOR,
                               D3DBLEND_INVSRCCOLOR,
                               D3DBLEND_SRCALPHA,
                               D3DBLEND_INVSRCALPHA,
                               D3DBLEND_DESTALPHA,
                               D3DBLEND_INVDESTALPHA,
                               D3DBLEND_DESTCOLOR,
                               D3DBLEND_INVDESTCOLOR,
                               D3DBLEND_SRCALPHASAT,
                               D3DBLEND_BOTHSRCALPHA,
                               D3DBLEND_BOTHINVSRCALPHA,
                               D3DBLEND_BLENDFACTOR,
                               D3DBLEND_INVBLENDFACTOR};
const D3DBLENDOP kAllOps[] = {D3DBLENDOP_ADD, D3DBLENDOP_SUBTRACT, D3DBLENDOP_REVSUBTRACT, D3DBLENDOP_MIN,
                              D3DBLENDOP_MAX};
const D3DCMPFUNC kAllCmps[] = {D3DCMP_NEVER,   D3DCMP_LESS,     D3DCMP_EQUAL,        D3DCMP_LESSEQUAL,
                               D3DCMP_GREATER, D3DCMP_NOTEQUAL, D3DCMP_GREATEREQUAL, D3DCMP_ALWAYS};

// D3DCMPFUNC by its documented meaning: does `a` (incoming) pass against `b` (reference)?
template <typename T>
bool cmpRef(D3DCMPFUNC f, T a, T b) {
    switch (f) {
        case D3DCMP_NEVER:
            return false;
        case D3DCMP_LESS:
            return a < b;
        case D3DCMP_EQUAL:
            return a == b;
        case D3DCMP_LESSEQUAL:
            return a <= b;
        case D3DCMP_GREATER:
            return a > b;
        case D3DCMP_NOTEQUAL:
            return a != b;
        case D3DCMP_GREATEREQUAL:
            return a >= b;
        case D3DCMP_ALWAYS:
            return true;
    }
    return false;
}

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

MergeState blendState(D3DBLEND s, D3DBLEND d, D3DBLENDOP op, Precision p) {
    MergeState st;
    st.blend = true;
    st.srcBlend = s, st.dstBlend = d, st.blendOp = op;
    st.blendFactor = 0x80c04011u;  // a = 0x80, r = 0xc0, g = 0x40, b = 0x11
    st.precision = p;
    return st;
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

// The stored depth code of z: the nearest of 2^bits - 1 steps, ties to even, computed exactly.
uint64_t depthCodeRef(float z, int bits) { return uint64_t(rhe(fromFloat(z) * Q{(I(1) << bits) - 1, 1})); }

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
uint32_t depthWord(const Image& img, uint32_t x) {
    uint32_t w = 0;
    std::memcpy(&w, img.texel(x, 0), img.format->bytes);
    return w;
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
