// The exact model of the output merger's tests (test_output_merger*.cpp): rationals of 128-bit
// integers with a half-even rounding, the D3D9 blend and compare formulas written from their
// reference pages, 8-bit, float and half targets and their texels, spans of shaded pixels run
// through mergePixels, and the depth codes. Never taken from the merger.
#pragma once

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "emu/format.h"
#include "emu/output_merger.h"
#include "emu/resources.h"

namespace mergermodel {

using namespace emu;
using ps11::Precision;

// ---- exact rationals -------------------------------------------------------------------------
using I = __int128;

inline I gcd128(I a, I b) {
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
inline Q mk(I n, I d) {
    if (d < 0) n = -n, d = -d;
    const I g = gcd128(n, d);
    return g > 1 ? Q{n / g, d / g} : Q{n, d};
}
inline Q operator+(Q a, Q b) { return mk(a.n * b.d + b.n * a.d, a.d * b.d); }
inline Q operator-(Q a, Q b) { return mk(a.n * b.d - b.n * a.d, a.d * b.d); }
inline Q operator*(Q a, Q b) { return mk(a.n * b.n, a.d * b.d); }
inline bool operator<(Q a, Q b) { return a.n * b.d < b.n * a.d; }
inline bool operator==(Q a, Q b) { return a.n * b.d == b.n * a.d; }
inline Q qmin(Q a, Q b) { return b < a ? b : a; }
inline Q qmax(Q a, Q b) { return a < b ? b : a; }
const Q kZeroQ{0, 1}, kOneQ{1, 1};

// round_half_even of an exact rational (floor division, then the tie rule).
inline int64_t rhe(Q r) {
    I q = r.n / r.d, m = r.n % r.d;
    if (m < 0) m += r.d, q -= 1;
    if (2 * m > r.d || (2 * m == r.d && (q & 1))) ++q;
    return int64_t(q);
}
// An exact float as a rational (every finite float is m * 2^e).
inline Q fromFloat(float f) {
    int e = 0;
    const double m = std::frexp(double(f), &e);  // f = m * 2^e, |m| in [0.5, 1)
    const I mant = I(std::ldexp(m, 53));         // exact: 53 bits
    e -= 53;
    return e >= 0 ? mk(mant * (I(1) << e), 1) : mk(mant, I(1) << (-e));
}
// The 8-bit store of a real value: saturate, then round_half_even(x * 255).
inline uint32_t byteOfQ(Q r) {
    if (r < kZeroQ) r = kZeroQ;
    if (kOneQ < r) r = kOneQ;
    return uint32_t(rhe(r * Q{255, 1}));
}

// ---- the D3D9 blend formulas ----------------------------------------------------------------
// Factor per the D3DBLEND reference page: channel c of (r, g, b, a).
inline Q factorRef(D3DBLEND b, int c, const Q* s, const Q* d, const Q* bf) {
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
inline void pairRef(D3DBLEND& s, D3DBLEND& d) {
    if (s == D3DBLEND_BOTHSRCALPHA)
        s = D3DBLEND_SRCALPHA, d = D3DBLEND_INVSRCALPHA;
    else if (s == D3DBLEND_BOTHINVSRCALPHA)
        s = D3DBLEND_INVSRCALPHA, d = D3DBLEND_SRCALPHA;
    else if (d == D3DBLEND_BOTHSRCALPHA)
        d = D3DBLEND_INVSRCALPHA;
    else if (d == D3DBLEND_BOTHINVSRCALPHA)
        d = D3DBLEND_SRCALPHA;
}
inline Q opRef(D3DBLENDOP op, Q s, Q fs, Q d, Q fd) {
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
inline std::array<Q, 4> blendRef(const MergeState& st, const Q* s, const Q* d) {
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
inline Image makeImage(D3DFORMAT f, uint32_t w, uint32_t h) {
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
inline std::array<uint32_t, 4> rgbaAt(const Image& img, uint32_t x, uint32_t y) {
    const uint8_t* p = img.texel(x, y);
    return {p[2], p[1], p[0], p[3]};
}
inline void setRgba(Image& img, uint32_t x, uint32_t y, std::array<uint32_t, 4> v) {
    uint8_t* p = img.texel(x, y);
    p[0] = uint8_t(v[2]), p[1] = uint8_t(v[1]), p[2] = uint8_t(v[0]), p[3] = uint8_t(v[3]);
}
inline float floatAt(const Image& img, uint32_t x, uint32_t y, int c) {
    float f;
    std::memcpy(&f, img.texel(x, y) + 4 * c, 4);
    return f;
}
inline uint16_t halfAt(const Image& img, uint32_t x, uint32_t y, int c) {
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

inline MergeStats run(const MergeState& st, const Span& span, Image* color, Image* depth = nullptr) {
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
inline bool cmpRef(D3DCMPFUNC f, T a, T b) {
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

inline MergeState blendState(D3DBLEND s, D3DBLEND d, D3DBLENDOP op, Precision p) {
    MergeState st;
    st.blend = true;
    st.srcBlend = s, st.dstBlend = d, st.blendOp = op;
    st.blendFactor = 0x80c04011u;  // a = 0x80, r = 0xc0, g = 0x40, b = 0x11
    st.precision = p;
    return st;
}

// The stored depth code of z: the nearest of 2^bits - 1 steps, ties to even, computed exactly.
inline uint64_t depthCodeRef(float z, int bits) { return uint64_t(rhe(fromFloat(z) * Q{(I(1) << bits) - 1, 1})); }

inline uint32_t depthWord(const Image& img, uint32_t x) {
    uint32_t w = 0;
    std::memcpy(&w, img.texel(x, 0), img.format->bytes);
    return w;
}

}  // namespace mergermodel
