// Unit tests of vertex processing (emu/vertex.h) and the rasteriser (emu/raster.h): the
// top-left fill rule (shared edges covered exactly once), pixel-centre and perspective-correct
// interpolation, 2×2 quads with helper lanes, clipping, culling, strip/fan winding, flat shading,
// texture-coordinate routing and transforms. Expected values are computed in the test from the
// D3D9 rules (barycentric formulas, the viewport equations), never taken from the code's output.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "emu/raster.h"
#include "emu/vertex.h"

using namespace emu;

namespace {

ScreenVertex sv(double x, double y, float rhw = 1.0f) {
    ScreenVertex v;
    v.x = x;
    v.y = y;
    v.rhw = rhw;
    return v;
}

ScreenTriangle tri(ScreenVertex a, ScreenVertex b, ScreenVertex c) { return ScreenTriangle{{a, b, c}}; }

constexpr uint64_t kU = uint64_t(1) << attrTex(0, 0);
constexpr uint64_t kV = uint64_t(1) << attrTex(0, 1);

// Live pixels of a triangle → count, through the span path (rasterizeRows).
void cover(const ScreenTriangle& t, const ClipRect& clip, std::map<std::pair<int, int>, int>& hits) {
    TriangleSetup s;
    if (!setupTriangle(t, 0, clip, s)) return;
    QuadSpan span;
    rasterizeRows(s, 0, 1 << 20, 0, false, span, [&](QuadSpan& sp) {
        for (int L = 0; L < sp.count; ++L)
            if (sp.live[L]) ++hits[{sp.x[L], sp.y[L]}];
    });
}

ClipRect rect(int x0, int y0, int x1, int y1) { return ClipRect{x0, y0, x1, y1}; }

// The top-left rule written as its definition: a pixel centre is inside when it is strictly
// inside, or on an edge and the point moved by an infinitesimal (ε, ε²) is inside — i.e. the edge
// is a left edge (inside to the right) or a horizontal top edge (inside below). Exact in int64 on
// the 1/256 grid.
bool insideRef(const ScreenTriangle& t, int px, int py) {
    int64_t X[3], Y[3];
    for (int i = 0; i < 3; ++i) {
        X[i] = std::llround(t.v[size_t(i)].x * 256);
        Y[i] = std::llround(t.v[size_t(i)].y * 256);
    }
    const int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
    if (area == 0) return false;
    const int64_t sign = area > 0 ? 1 : -1;
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3;
        const int64_t dx = X[j] - X[i], dy = Y[j] - Y[i];
        // E(P) = dx·(Py − Yi) − dy·(Px − Xi), positive inside for area > 0.
        const int64_t e = sign * (dx * (int64_t(py) * 256 - Y[i]) - dy * (int64_t(px) * 256 - X[i]));
        const int64_t dEdx = -sign * dy, dEdy = sign * dx;
        if (e > 0) continue;
        if (e < 0) return false;
        if (dEdx > 0 || (dEdx == 0 && dEdy > 0)) continue;  // moved by (ε, ε²): inside
        return false;
    }
    return true;
}

}  // namespace

TEST_CASE("raster: a rectangle from (0,0) to (5,5) as two triangles covers 25 pixels once", "[raster]") {
    // D3D9 "Rasterization Rules": pixel centres at integers, top-left rule.
    for (int diag = 0; diag < 2; ++diag) {
        std::map<std::pair<int, int>, int> hits;
        const ClipRect clip = rect(0, 0, 64, 64);
        if (diag == 0) {
            cover(tri(sv(0, 0), sv(5, 0), sv(5, 5)), clip, hits);
            cover(tri(sv(0, 0), sv(5, 5), sv(0, 5)), clip, hits);
        } else {
            cover(tri(sv(0, 0), sv(5, 0), sv(0, 5)), clip, hits);
            cover(tri(sv(5, 0), sv(5, 5), sv(0, 5)), clip, hits);
        }
        CHECK(hits.size() == 25);
        for (auto& [p, n] : hits) {
            CHECK(n == 1);
            CHECK(p.first >= 0);
            CHECK(p.first < 5);
            CHECK(p.second >= 0);
            CHECK(p.second < 5);
        }
    }
}

TEST_CASE("raster: top and left edges through pixel centres are covered, right and bottom are not", "[raster]") {
    // Triangle (2,2) (8,2) (2,8): top edge y = 2 and left edge x = 2 through centres, the
    // hypotenuse x + y = 10 through centres too (a right/bottom edge: excluded).
    std::map<std::pair<int, int>, int> hits;
    cover(tri(sv(2, 2), sv(8, 2), sv(2, 8)), rect(0, 0, 16, 16), hits);
    std::set<std::pair<int, int>> expected;
    for (int y = 2; y < 8; ++y)
        for (int x = 2; x < 8; ++x)
            if (x + y < 10) expected.insert({x, y});
    std::set<std::pair<int, int>> got;
    for (auto& [p, n] : hits) got.insert(p);
    CHECK(got == expected);
    CHECK(hits.count({2, 2}) == 1);  // the top-left vertex itself
    CHECK(hits.count({8, 2}) == 0);
    CHECK(hits.count({5, 5}) == 0);  // on the hypotenuse
}

TEST_CASE("raster: a fan around a pixel centre covers every pixel exactly once", "[raster]") {
    // Centre (10, 10) on a pixel centre, rim vertices on pixel centres and in between.
    const double rim[][2] = {{4, 4}, {10, 3}, {16, 4}, {17, 10.5}, {16, 16}, {10, 17}, {4, 16}, {3.25, 10}};
    const int n = 8;
    for (int wind = 0; wind < 2; ++wind) {
        std::map<std::pair<int, int>, int> hits;
        for (int i = 0; i < n; ++i) {
            const auto& a = rim[i];
            const auto& b = rim[(i + 1) % n];
            if (wind == 0)
                cover(tri(sv(10, 10), sv(a[0], a[1]), sv(b[0], b[1])), rect(0, 0, 32, 32), hits);
            else
                cover(tri(sv(10, 10), sv(b[0], b[1]), sv(a[0], a[1])), rect(0, 0, 32, 32), hits);
        }
        CHECK(hits.count({10, 10}) == 1);
        for (auto& [p, k] : hits) CHECK(k == 1);
        // Every pixel strictly inside the rim's bounding box core is covered.
        for (int y = 5; y < 16; ++y)
            for (int x = 5; x < 16; ++x) CHECK(hits.count({x, y}) == 1);
    }
}

TEST_CASE("raster: a jittered sub-pixel mesh covers its pixels once; coverage equals the rule's definition",
          "[raster]") {
    std::mt19937 rng(1234);
    std::uniform_int_distribution<int> jitter(-100, 100);  // 1/256 pixel units
    const int N = 9;
    std::vector<std::array<double, 2>> pts(size_t(N * N));
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            const bool border = i == 0 || j == 0 || i == N - 1 || j == N - 1;
            pts[size_t(j * N + i)] = {2.0 + 5 * i + (border ? 0 : jitter(rng) / 256.0),
                                      2.0 + 5 * j + (border ? 0 : jitter(rng) / 256.0)};
        }
    // Some interior points exactly on pixel centres and half-pixel positions (ties).
    pts[size_t(2 * N + 2)] = {12, 12};
    pts[size_t(3 * N + 4)] = {22.5, 17};
    std::map<std::pair<int, int>, int> hits;
    const ClipRect clip = rect(0, 0, 64, 64);
    std::vector<ScreenTriangle> tris;
    for (int j = 0; j + 1 < N; ++j)
        for (int i = 0; i + 1 < N; ++i) {
            auto P = [&](int a, int b) { return sv(pts[size_t(b * N + a)][0], pts[size_t(b * N + a)][1]); };
            if ((i + j) & 1) {
                tris.push_back(tri(P(i, j), P(i + 1, j), P(i + 1, j + 1)));
                tris.push_back(tri(P(i, j), P(i + 1, j + 1), P(i, j + 1)));
            } else {
                tris.push_back(tri(P(i, j), P(i + 1, j), P(i, j + 1)));
                tris.push_back(tri(P(i + 1, j + 1), P(i, j + 1), P(i + 1, j)));  // other winding
            }
        }
    for (const ScreenTriangle& t : tris) {
        std::map<std::pair<int, int>, int> one;
        cover(t, clip, one);
        std::set<std::pair<int, int>> expected;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x)
                if (insideRef(t, x, y)) expected.insert({x, y});
        std::set<std::pair<int, int>> got;
        for (auto& [p, k] : one) got.insert(p);
        CHECK(got == expected);
        for (auto& [p, k] : one) hits[p] += k;
    }
    // The mesh spans [2, 42]²: pixels 2..41 in x and y, each exactly once.
    CHECK(hits.size() == 40 * 40);
    for (auto& [p, k] : hits) {
        CHECK(k == 1);
        CHECK(p.first >= 2);
        CHECK(p.first < 42);
    }
}

TEST_CASE("raster: the clip rectangle limits coverage", "[raster]") {
    std::map<std::pair<int, int>, int> hits;
    cover(tri(sv(-10, -10), sv(50, -10), sv(-10, 50)), rect(3, 5, 9, 8), hits);
    CHECK(hits.size() == 6 * 3);
    for (auto& [p, k] : hits) {
        CHECK(p.first >= 3);
        CHECK(p.first < 9);
        CHECK(p.second >= 5);
        CHECK(p.second < 8);
    }
}

TEST_CASE("raster: coveredColumns is the union of rowCoverage's rows", "[raster]") {
    // Random triangles (slivers, sub-pixel ones, ones far outside the clip, both windings, huge
    // ones): the columns stepped from row to row equal those of rowCoverage row by row.
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> near(-30.0, 130.0), far(-5000.0, 5000.0), tiny(-0.7, 0.7);
    const ClipRect clip{3, 5, 97, 83};
    int compared = 0, empty = 0;
    for (int i = 0; i < 20000; ++i) {
        ScreenTriangle t;
        const int shape = i % 4;
        for (ScreenVertex& v : t.v) {
            v = shape == 1 ? sv(far(rng), far(rng)) : sv(near(rng), near(rng));
            if (shape == 2 && &v != &t.v[0]) v = sv(t.v[0].x + tiny(rng), t.v[0].y + near(rng) / 10);
            if (shape == 3 && &v == &t.v[2]) v = sv(t.v[1].x, t.v[0].y);  // a horizontal and a vertical edge
        }
        TriangleSetup s;
        if (!setupTriangle(t, 0, clip, s)) continue;
        int lo = clip.x1, hi = clip.x0;
        for (int y = s.yMin; y < s.yMax; ++y) {
            int xl = 0, xr = 0;
            if (rowCoverage(s, y, xl, xr)) lo = std::min(lo, xl), hi = std::max(hi, xr);
        }
        int xlo = -1, xhi = -1;
        const bool any = coveredColumns(s, xlo, xhi);
        REQUIRE(any == (lo < hi));
        if (any) {
            INFO("triangle " << i);
            REQUIRE(xlo == lo);
            REQUIRE(xhi == hi);
            ++compared;
        } else {
            ++empty;
        }
    }
    CHECK(compared > 5000);
    CHECK(empty > 100);
}

TEST_CASE("raster: the half-pixel quad gives every pixel the coordinate of its own centre", "[raster]") {
    // Quad (−0.5, −0.5)–(W − 0.5, H − 0.5), u 0..1, v 0..1: pixel x gets u = (x + 0.5)/W.
    const int W = 1920, H = 6;
    auto V = [](double x, double y, float u, float v) {
        ScreenVertex s = sv(x, y);
        s.attr[size_t(attrTex(0, 0))] = u;
        s.attr[size_t(attrTex(0, 1))] = v;
        return s;
    };
    const ScreenVertex a = V(-0.5, -0.5, 0, 0), b = V(W - 0.5, -0.5, 1, 0), c = V(W - 0.5, H - 0.5, 1, 1),
                       d = V(-0.5, H - 0.5, 0, 1);
    int covered = 0;
    double worst = 0;
    for (const ScreenTriangle& t : {tri(a, b, c), tri(a, c, d)}) {
        TriangleSetup s;
        REQUIRE(setupTriangle(t, kU | kV, rect(0, 0, W, H), s));
        CHECK_FALSE(s.perspective);
        QuadSpan span;
        rasterizeRows(s, 0, H, kU | kV, false, span, [&](QuadSpan& sp) {
            for (int L = 0; L < sp.count; ++L) {
                if (!sp.live[L]) continue;
                ++covered;
                const double u = (sp.x[L] + 0.5) / W, v = (sp.y[L] + 0.5) / H;
                worst = std::max(worst, std::fabs(sp.attr[attrTex(0, 0)][L] - u) / std::ldexp(1.0, -24));
                CHECK(std::fabs(sp.attr[attrTex(0, 1)][L] - v) <= std::ldexp(1.0, -23));
            }
        });
    }
    CHECK(covered == W * H);
    INFO("worst error in units of 2^-24: " << worst);
    CHECK(worst <= 2.0);  // within 2 ulp of values in [0.5, 1)
}

TEST_CASE("raster: attributes are perspective-correct", "[raster]") {
    // rhw differs per vertex: u(x, y) = Σ bᵢ·uᵢ·rhwᵢ / Σ bᵢ·rhwᵢ with screen barycentrics bᵢ.
    const double P[3][2] = {{3.3, 2.1}, {60.7, 9.4}, {12.2, 50.9}};
    const float rhw[3] = {1.0f, 0.125f, 0.4f};
    const float U[3] = {0.0f, 4.0f, -2.0f};
    const float R[3] = {0.1f, 0.9f, 0.5f};
    ScreenTriangle t;
    for (int i = 0; i < 3; ++i) {
        t.v[size_t(i)] = sv(P[i][0], P[i][1], rhw[i]);
        t.v[size_t(i)].attr[size_t(attrTex(0, 0))] = U[i];
        t.v[size_t(i)].attr[kAttrDiffuse] = R[i];
        t.v[size_t(i)].z = 0.25f * float(i);
    }
    const uint64_t used = kU | 1;
    TriangleSetup s;
    REQUIRE(setupTriangle(t, used, rect(0, 0, 64, 64), s));
    CHECK(s.perspective);
    // Snapped positions (all on the 1/256 grid? no: use the snapped values as the rasteriser does).
    double X[3], Y[3];
    for (int i = 0; i < 3; ++i) {
        X[i] = std::llround(P[i][0] * 256) / 256.0;
        Y[i] = std::llround(P[i][1] * 256) / 256.0;
    }
    const double area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    int n = 0;
    QuadSpan span;
    rasterizeRows(s, 0, 64, used, true, span, [&](QuadSpan& sp) {
        for (int L = 0; L < sp.count; ++L) {
            if (!sp.live[L]) continue;
            ++n;
            const double x = sp.x[L], y = sp.y[L];
            const double b1 = ((x - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (y - Y[0])) / area;
            const double b2 = ((X[1] - X[0]) * (y - Y[0]) - (x - X[0]) * (Y[1] - Y[0])) / area;
            const double b0 = 1 - b1 - b2;
            const double den = b0 * rhw[0] + b1 * rhw[1] + b2 * rhw[2];
            const double u = (b0 * U[0] * rhw[0] + b1 * U[1] * rhw[1] + b2 * U[2] * rhw[2]) / den;
            const double r = (b0 * R[0] * rhw[0] + b1 * R[1] * rhw[1] + b2 * R[2] * rhw[2]) / den;
            const double z = b1 * 0.25 + b2 * 0.5;  // z is linear on the screen
            CHECK(std::fabs(sp.attr[attrTex(0, 0)][L] - u) <= 1e-5);
            CHECK(std::fabs(sp.attr[kAttrDiffuse][L] - r) <= 1e-6);
            CHECK(std::fabs(sp.z[L] - z) <= 1e-6);
        }
    });
    CHECK(n > 500);
}

TEST_CASE("raster: spans are 2x2 quads with helper lanes", "[raster]") {
    // A small triangle covering only pixel (3, 5): its quad is (2..3, 4..5).
    ScreenTriangle t = tri(sv(2.5625, 4.625), sv(3.5, 4.625), sv(3.5, 5.5));  // on the 1/256 grid
    for (int i = 0; i < 3; ++i) t.v[size_t(i)].attr[size_t(attrTex(0, 0))] = float(t.v[size_t(i)].x) * 2.0f;
    TriangleSetup s;
    REQUIRE(setupTriangle(t, kU, rect(0, 0, 16, 16), s));
    int spans = 0;
    QuadSpan span;
    rasterizeRows(s, 0, 16, kU, false, span, [&](QuadSpan& sp) {
        ++spans;
        REQUIRE(sp.count == 4);
        const int ex[4] = {2, 3, 2, 3}, ey[4] = {4, 4, 5, 5};
        for (int L = 0; L < 4; ++L) {
            CHECK(sp.x[L] == ex[L]);
            CHECK(sp.y[L] == ey[L]);
            CHECK(sp.live[L] == (L == 3 ? 1 : 0));
            // u = 2x everywhere, helpers included (the plane extends beyond the triangle).
            CHECK(sp.attr[attrTex(0, 0)][L] == Approx(2.0 * ex[L]).margin(1e-5));
        }
    });
    CHECK(spans == 1);
}

TEST_CASE("raster: a wide row pair is cut into spans of at most kMaxSpan lanes", "[raster]") {
    const int W = ps11::kMaxSpan + ps11::kMaxSpan / 2 + 44;  // 2W lanes = 3 kMaxSpan + 88
    TriangleSetup s;
    REQUIRE(setupTriangle(tri(sv(-0.5, -0.5), sv(W - 0.5, -0.5), sv(-0.5, 1e5)), 0, rect(0, 0, W, 2), s));
    std::vector<int> counts;
    QuadSpan span;
    int live = 0;
    rasterizeRows(s, 0, 2, 0, false, span, [&](QuadSpan& sp) {
        counts.push_back(sp.count);
        for (int L = 0; L < sp.count; ++L) live += sp.live[L];
    });
    REQUIRE(counts.size() == 4);
    CHECK(counts[0] == ps11::kMaxSpan);
    CHECK(counts[1] == ps11::kMaxSpan);
    CHECK(counts[2] == ps11::kMaxSpan);
    CHECK(counts[3] == 88);
    CHECK(live == 2 * W);
}

// ---- vertex processing ----

namespace {

struct XyzVertex {
    float x, y, z;
    DWORD diffuse;
    float u, v;
};

DeviceState stateFor(UINT w, UINT h, DWORD fvf) {
    DeviceState st;
    st.viewport = D3DVIEWPORT9{0, 0, w, h, 0.0f, 1.0f};
    st.fvf = fvf;
    st.renderStates[D3DRS_CULLMODE] = D3DCULL_NONE;
    return st;
}

const DWORD kXyzFvf = D3DFVF_XYZ | D3DFVF_DIFFUSE | D3DFVF_TEX1;

std::vector<ScreenTriangle> run(const DeviceState& st, D3DPRIMITIVETYPE type, uint32_t count, const void* data,
                                uint32_t stride, uint64_t used = ~uint64_t(0), VertexStats* stats = nullptr) {
    std::string err;
    auto layout = parseFvf(st.fvf, err);
    REQUIRE(layout);
    VertexSetup setup;
    setup.layout = &*layout;
    setup.usedAttrs = used;
    std::vector<ScreenTriangle> out;
    processTriangles(st, setup, type, 0, count, static_cast<const uint8_t*>(data), stride, out, stats);
    return out;
}

}  // namespace

TEST_CASE("vertex: FVF layouts, sizes and refusals", "[raster][vertex]") {
    std::string err;
    auto L = parseFvf(D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_SPECULAR | D3DFVF_TEX3 | D3DFVF_TEXCOORDSIZE1(1) |
                          D3DFVF_TEXCOORDSIZE4(2),
                      err);
    REQUIRE(L);
    CHECK(L->pretransformed);
    CHECK(L->diffuseOffset == 16);
    CHECK(L->specularOffset == 20);
    CHECK(L->texCount == 3);
    CHECK(L->texSize[0] == 2);
    CHECK(L->texSize[1] == 1);
    CHECK(L->texSize[2] == 4);
    CHECK(L->texOffset[0] == 24);
    CHECK(L->texOffset[1] == 32);
    CHECK(L->texOffset[2] == 36);
    CHECK(L->size == 52);
    auto N = parseFvf(
        D3DFVF_XYZ | D3DFVF_NORMAL | D3DFVF_PSIZE | D3DFVF_DIFFUSE | D3DFVF_TEX1 | D3DFVF_TEXCOORDSIZE3(0), err);
    REQUIRE(N);
    CHECK_FALSE(N->pretransformed);
    CHECK(N->diffuseOffset == 28);  // 12 xyz + 12 normal + 4 psize
    CHECK(N->texSize[0] == 3);
    CHECK(N->size == 44);
    CHECK_FALSE(parseFvf(D3DFVF_DIFFUSE, err));      // no position
    CHECK_FALSE(parseFvf(0x0006 /* XYZB1 */, err));  // blend weights
    CHECK_FALSE(parseFvf(0x4002 /* XYZW */, err));
    CHECK_FALSE(parseFvf(D3DFVF_XYZRHW | D3DFVF_NORMAL, err));
    CHECK_FALSE(parseFvf(D3DFVF_XYZ | 0x0900, err));  // 9 texture sets
    CHECK_FALSE(parseFvf(D3DFVF_XYZ | 0x1000 /* LASTBETA_UBYTE4 */, err));
    CHECK(vertexCountOf(D3DPT_TRIANGLELIST, 4) == 12);
    CHECK(vertexCountOf(D3DPT_TRIANGLESTRIP, 4) == 6);
    CHECK(vertexCountOf(D3DPT_TRIANGLEFAN, 4) == 6);
}

TEST_CASE("vertex: World·View·Projection with row vectors and the viewport equations", "[raster][vertex]") {
    DeviceState st = stateFor(0, 0, kXyzFvf);
    st.viewport = D3DVIEWPORT9{10, 20, 100, 50, 0.2f, 0.6f};
    // World translates by (0.5, 0, 0); projection scales w by 2 (m[3][3] = 2) → x/w halves.
    st.world.m[3][0] = 0.5f;
    st.projection.m[3][3] = 2.0f;
    const XyzVertex v[3] = {
        {-1.5f, 1, 0.5f, 0xff000000, 0, 0}, {0.5f, 1, 0.5f, 0xff000000, 1, 0}, {-1.5f, -1, 0.5f, 0xff000000, 0, 1}};
    auto out = run(st, D3DPT_TRIANGLELIST, 1, v, sizeof(XyzVertex));
    REQUIRE(out.size() == 1);
    // Vertex 0: clip (−1, 1, 0.5, 2) → ndc (−0.5, 0.5, 0.25): x = 10 + (1 − 0.5)·50 = 35,
    // y = 20 + (1 − 0.5)·25 = 32.5, z = 0.2 + 0.25·0.4 = 0.3, rhw = 0.5.
    CHECK(out[0].v[0].x == Approx(35.0));
    CHECK(out[0].v[0].y == Approx(32.5));
    CHECK(out[0].v[0].z == Approx(0.3f));
    CHECK(out[0].v[0].rhw == Approx(0.5f));
    // Vertex 1: clip (1, 1, 0.5, 2) → x = 10 + 1.5·50 = 85.
    CHECK(out[0].v[1].x == Approx(85.0));
    // Vertex 2: clip (−1, −1) → y = 20 + 1.5·25 = 57.5.
    CHECK(out[0].v[2].y == Approx(57.5));
    CHECK(out[0].v[2].attr[size_t(attrTex(0, 1))] == 1.0f);
}

TEST_CASE("vertex: homogeneous clipping against near, far and w <= 0", "[raster][vertex]") {
    DeviceState st = stateFor(64, 64, kXyzFvf);
    VertexStats stats;
    // Entirely behind the near plane, beyond the far plane, and in front of the eye with w < 0.
    const XyzVertex behind[3] = {{-1, -1, -0.5f, 0, 0, 0}, {1, -1, -0.1f, 0, 0, 0}, {0, 1, -0.2f, 0, 0, 0}};
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, behind, sizeof(XyzVertex), ~0ull, &stats).empty());
    CHECK(stats.clipped == 1);
    const XyzVertex far[3] = {{-1, -1, 1.5f, 0, 0, 0}, {1, -1, 1.1f, 0, 0, 0}, {0, 1, 2.0f, 0, 0, 0}};
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, far, sizeof(XyzVertex)).empty());
    DeviceState neg = st;
    neg.projection.m[3][3] = -1.0f;  // w = −1 for every vertex
    const XyzVertex mid[3] = {{-1, -1, 0.5f, 0, 0, 0}, {1, -1, 0.5f, 0, 0, 0}, {0, 1, 0.5f, 0, 0, 0}};
    CHECK(run(neg, D3DPT_TRIANGLELIST, 1, mid, sizeof(XyzVertex)).empty());

    // Crossing the near plane: z = −1 at the left, +1 at the right (z = x with w = 1), u = x.
    const XyzVertex cross[3] = {{-1, -1, -1, 0, -1, 0}, {1, -1, 1, 0, 1, 0}, {1, 1, 1, 0, 1, 0}};
    auto out = run(st, D3DPT_TRIANGLELIST, 1, cross, sizeof(XyzVertex));
    REQUIRE(!out.empty());
    for (const ScreenTriangle& t : out)
        for (const ScreenVertex& v : t.v) {
            CHECK(v.z >= -1e-6f);
            CHECK(v.z <= 1.0f);
            // The cut is at ndc x = 0, i.e. screen x = 32 and nothing is left of it; u = z there.
            CHECK(v.x >= 32.0 - 1e-9);
            CHECK(v.attr[size_t(attrTex(0, 0))] == Approx(v.z).margin(1e-6));
        }
}

TEST_CASE("vertex: culling follows D3DRS_CULLMODE on the screen winding", "[raster][vertex]") {
    struct Rhw {
        float x, y, z, rhw;
    };
    // (0,0) (10,0) (0,10) is clockwise on the screen (y down); the reverse is counter-clockwise.
    const Rhw cw[3] = {{0, 0, 0, 1}, {10, 0, 0, 1}, {0, 10, 0, 1}};
    const Rhw ccw[3] = {{0, 0, 0, 1}, {0, 10, 0, 1}, {10, 0, 0, 1}};
    DeviceState st = stateFor(32, 32, D3DFVF_XYZRHW);
    st.renderStates[D3DRS_CULLMODE] = D3DCULL_CCW;  // the D3D9 default
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, cw, sizeof(Rhw)).size() == 1);
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, ccw, sizeof(Rhw)).empty());
    st.renderStates[D3DRS_CULLMODE] = D3DCULL_CW;
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, cw, sizeof(Rhw)).empty());
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, ccw, sizeof(Rhw)).size() == 1);
    st.renderStates[D3DRS_CULLMODE] = D3DCULL_NONE;
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, cw, sizeof(Rhw)).size() == 1);
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, ccw, sizeof(Rhw)).size() == 1);
    // Degenerate (collinear) triangles are dropped.
    const Rhw line[3] = {{0, 0, 0, 1}, {5, 5, 0, 1}, {10, 10, 0, 1}};
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, line, sizeof(Rhw)).empty());
}

TEST_CASE("vertex: strips alternate the winding, fans keep it; flat shading uses the first vertex",
          "[raster][vertex]") {
    struct V {
        float x, y, z, rhw;
        DWORD diffuse, specular;
    };
    // A zig-zag strip over 4 columns, clockwise first triangle: all triangles must survive CCW culling.
    const V strip[6] = {{0, 0, 0, 1, 0xff000001, 0x10000000},  {0, 10, 0, 1, 0xff000002, 0x20000000},
                        {10, 0, 0, 1, 0xff000003, 0x30000000}, {10, 10, 0, 1, 0xff000004, 0x40000000},
                        {20, 0, 0, 1, 0xff000005, 0x50000000}, {20, 10, 0, 1, 0xff000006, 0x60000000}};
    DeviceState st = stateFor(32, 32, D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_SPECULAR);
    st.renderStates[D3DRS_CULLMODE] = D3DCULL_CW;  // first triangle (0,0) (0,10) (10,0) is counter-clockwise
    auto out = run(st, D3DPT_TRIANGLESTRIP, 4, strip, sizeof(V));
    REQUIRE(out.size() == 4);
    st.renderStates[D3DRS_SHADEMODE] = D3DSHADE_FLAT;
    out = run(st, D3DPT_TRIANGLESTRIP, 4, strip, sizeof(V));
    REQUIRE(out.size() == 4);
    for (size_t t = 0; t < 4; ++t) {
        // Triangle t is shaded with vertex t's diffuse (blue = t + 1); fog (specular alpha) still varies.
        for (const ScreenVertex& v : out[t].v) CHECK(v.attr[kAttrDiffuse + 2] == Approx((t + 1) / 255.0));
        std::set<float> fog;
        for (const ScreenVertex& v : out[t].v) fog.insert(v.attr[kAttrSpecular + 3]);
        CHECK(fog.size() == 3);
    }
    // A fan around (10, 10): triangle t is (v[t+1], v[t+2], v[0]) and flat-shaded with v[t+1].
    const V fan[5] = {{10, 10, 0, 1, 0xff000001, 0},
                      {0, 0, 0, 1, 0xff000002, 0},
                      {20, 0, 0, 1, 0xff000003, 0},
                      {20, 20, 0, 1, 0xff000004, 0},
                      {0, 20, 0, 1, 0xff000005, 0}};
    st.renderStates[D3DRS_CULLMODE] = D3DCULL_CCW;  // the fan is clockwise on the screen
    out = run(st, D3DPT_TRIANGLEFAN, 3, fan, sizeof(V));
    REQUIRE(out.size() == 3);
    for (size_t t = 0; t < 3; ++t) {
        CHECK(out[t].v[2].x == 10.0);  // the hub is the third vertex
        for (const ScreenVertex& v : out[t].v) CHECK(v.attr[kAttrDiffuse + 2] == Approx((t + 2) / 255.0));
    }
    // Gouraud keeps each vertex's colour.
    st.renderStates[D3DRS_SHADEMODE] = D3DSHADE_GOURAUD;
    out = run(st, D3DPT_TRIANGLEFAN, 3, fan, sizeof(V));
    CHECK(out[0].v[0].attr[kAttrDiffuse + 2] == Approx(2 / 255.0));
    CHECK(out[0].v[2].attr[kAttrDiffuse + 2] == Approx(1 / 255.0));
}

TEST_CASE("vertex: TEXCOORDINDEX routes sets to slots; texture transforms apply to XYZ, not XYZRHW",
          "[raster][vertex]") {
    struct V {
        float x, y, z;
        float s0[2];
        float s1[2];
    };
    const V v[3] = {{-1, -1, 0.5f, {0.1f, 0.2f}, {0.7f, 0.8f}},
                    {1, -1, 0.5f, {0.3f, 0.4f}, {0.5f, 0.6f}},
                    {1, 1, 0.5f, {0.0f, 0.0f}, {0.25f, 0.75f}}};
    DeviceState st = stateFor(64, 64, D3DFVF_XYZ | D3DFVF_TEX2);
    st.stageStates[0][D3DTSS_TEXCOORDINDEX] = 1;  // slot 0 reads set 1
    st.stageStates[1][D3DTSS_TEXCOORDINDEX] = 5;  // no set 5: defaults (0, 0, 0, 1)
    auto out = run(st, D3DPT_TRIANGLELIST, 1, v, sizeof(V));
    REQUIRE(out.size() == 1);
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 0))] == 0.7f);
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 1))] == 0.8f);
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 2))] == 0.0f);
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 3))] == 1.0f);
    CHECK(out[0].v[1].attr[size_t(attrTex(1, 0))] == 0.0f);
    CHECK(out[0].v[1].attr[size_t(attrTex(1, 3))] == 1.0f);

    // COUNT2 with a matrix that scales u by 2 and translates v by 0.5 in the row D3D uses for a
    // 2-component set (the third row: the input is (u, v, 1, 0)).
    st.stageStates[0][D3DTSS_TEXTURETRANSFORMFLAGS] = D3DTTFF_COUNT2;
    st.texture[0].m[0][0] = 2.0f;
    st.texture[0].m[2][1] = 0.5f;
    out = run(st, D3DPT_TRIANGLELIST, 1, v, sizeof(V));
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 0))] == Approx(1.4f));
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 1))] == Approx(1.3f));
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 3))] == 1.0f);
    // COUNT1 is ignored (as native D3D9 in Wine's tests).
    st.stageStates[0][D3DTSS_TEXTURETRANSFORMFLAGS] = D3DTTFF_COUNT1;
    out = run(st, D3DPT_TRIANGLELIST, 1, v, sizeof(V));
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 0))] == 0.7f);

    // XYZRHW: the matrix is not applied.
    struct R {
        float x, y, z, rhw;
        float s0[2];
    };
    const R r[3] = {{0, 0, 0, 1, {0.1f, 0.2f}}, {10, 0, 0, 1, {0.3f, 0.4f}}, {0, 10, 0, 1, {0.5f, 0.6f}}};
    DeviceState rs = stateFor(64, 64, D3DFVF_XYZRHW | D3DFVF_TEX1);
    rs.stageStates[0][D3DTSS_TEXTURETRANSFORMFLAGS] = D3DTTFF_COUNT2;
    rs.texture[0].m[0][0] = 2.0f;
    out = run(rs, D3DPT_TRIANGLELIST, 1, r, sizeof(R));
    REQUIRE(out.size() == 1);
    CHECK(out[0].v[0].attr[size_t(attrTex(0, 0))] == 0.1f);
}

TEST_CASE("vertex: XYZRHW beyond the guard band is clipped in screen space, perspective-correctly",
          "[raster][vertex]") {
    struct R {
        float x, y, z, rhw;
        float s0[2];
    };
    // One vertex far to the right: the polygon is cut at x = kGuardBand.
    const float far = 1e7f;
    const R r[3] = {{0, 0, 0, 1, {0, 0}}, {far, 0, 0, 0.5f, {1, 0}}, {0, 10, 0, 1, {0, 1}}};
    DeviceState st = stateFor(64, 64, D3DFVF_XYZRHW | D3DFVF_TEX1);
    auto out = run(st, D3DPT_TRIANGLELIST, 1, r, sizeof(R));
    REQUIRE(!out.empty());
    for (const ScreenTriangle& t : out)
        for (const ScreenVertex& v : t.v) {
            CHECK(v.x <= kGuardBand);
            if (v.x == kGuardBand && v.y == 0) {
                // On the edge from (0, 0, rhw 1, u 0) to (far, 0, rhw 0.5, u 1) at s = G/far:
                // rhw = 1 − 0.5s, u = (0.5·s)/rhw.
                const double s = kGuardBand / far;
                CHECK(v.rhw == Approx(1 - 0.5 * s));
                CHECK(v.attr[size_t(attrTex(0, 0))] == Approx(0.5 * s / (1 - 0.5 * s)));
            }
        }
    // Non-finite positions and rhw <= 0 are dropped.
    const R bad[3] = {{0, 0, 0, 0, {0, 0}}, {10, 0, 0, 1, {0, 0}}, {0, 10, 0, 1, {0, 0}}};
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, bad, sizeof(R)).empty());
    const R nan[3] = {{NAN, 0, 0, 1, {0, 0}}, {10, 0, 0, 1, {0, 0}}, {0, 10, 0, 1, {0, 0}}};
    CHECK(run(st, D3DPT_TRIANGLELIST, 1, nan, sizeof(R)).empty());
}

TEST_CASE("raster: constant attributes are exact and follow each triangle through a reused span", "[raster]") {
    QuadSpan span;
    for (int round = 0; round < 3; ++round)
        for (float value : {0.3f, -2.0f, 0.3f}) {
            // Wider and narrower triangles alternate, so fills of different lengths are reused.
            const double w = round == 1 ? 7.0 : 40.0;
            ScreenTriangle t = tri(sv(0, 0, 0.5f), sv(w, 0, 0.25f), sv(0, 9, 1.0f));
            for (ScreenVertex& v : t.v) v.attr[size_t(attrTex(0, 3))] = value;
            TriangleSetup s;
            REQUIRE(setupTriangle(t, uint64_t(1) << attrTex(0, 3), rect(0, 0, 64, 64), s));
            int n = 0;
            rasterizeRows(s, 0, 64, uint64_t(1) << attrTex(0, 3), false, span, [&](QuadSpan& sp) {
                for (int L = 0; L < sp.count; ++L) {
                    ++n;
                    CHECK(sp.attr[attrTex(0, 3)][L] == value);  // exact despite the perspective rhw
                }
            });
            CHECK(n > 0);
        }
}
