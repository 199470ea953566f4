// The rasteriser: exact fixed-point coverage with the top-left rule, attribute planes, and
// spans of 2×2 quads for the executor.
#include "emu/raster.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace emu {

namespace {

constexpr int64_t kOne = int64_t(1) << kSubPixelBits;

// floor(n / d) and ceil(n / d) for d > 0.
int64_t floorDiv(int64_t n, int64_t d) { return n >= 0 ? n / d : -((-n + d - 1) / d); }
int64_t ceilDiv(int64_t n, int64_t d) { return n >= 0 ? (n + d - 1) / d : -((-n) / d); }

// Lane layout of a span: lane L belongs to quad L/4; its column offset within the span is
// 2·(L/4) + (L & 1) and its row is (L >> 1) & 1.
struct LaneTable {
    alignas(32) int32_t colInt[ps11::kMaxSpan];
    alignas(32) float col[ps11::kMaxSpan];
    alignas(32) int32_t row[ps11::kMaxSpan];
    LaneTable() {
        for (int L = 0; L < ps11::kMaxSpan; ++L) {
            colInt[L] = 2 * (L >> 2) + (L & 1);
            col[L] = float(colInt[L]);
            row[L] = (L >> 1) & 1;
        }
    }
};
const LaneTable kLanes;

// Four float lanes (GCC/Clang vector extension): one 2×2 quad.
typedef float Quad4 __attribute__((vector_size(16)));

// Fills lanes [0, n) with the plane's values over the span whose top-left lane is pixel
// (x0, y0). A lane's value depends on its pixel alone, never on where the span starts:
// value(x, y) = float(rowBase(y)) + float(dx) · float(x), rowBase(y) = base + dx·(0 − ox) +
// dy·(y − oy) in double (planeRowBase), then one float multiply and one float add
// (planeValue). The aligned-pass path (emu/aligned_pass.h) relies on that to build its
// per-column and per-row tables from the same formula. One quad per step.
void fillPlane(const Plane& p, double ox, double oy, int x0, int y0, int n, float* out) {
    const float f0 = float(planeRowBase(p, ox, oy, y0)), f1 = float(planeRowBase(p, ox, oy, y0 + 1));
    const float fdx = float(p.dx), fx0 = float(x0);
    const Quad4 base = {f0, f0, f1, f1};
    const Quad4 d = {fdx, fdx, fdx, fdx};
    const Quad4 start = {fx0, fx0, fx0, fx0};
    // Columns from a table (no loop-carried dependency: a running column would serialise the adds).
    for (int q = 0; q < n / 4; ++q) {
        Quad4 col;
        std::memcpy(&col, kLanes.col + 4 * q, sizeof col);
        const Quad4 r = base + d * (start + col);  // start + col = x exactly (x < 2^24)
        std::memcpy(out + 4 * q, &r, sizeof r);
    }
}

// The attributes `used` (and z when `wantZ`) of a span's n lanes, their pixels set:
// `fill(plane, out)` writes a plane's values over the lanes (fillPlane for quads, fillPlaneRow
// for a row). With perspective the planes are of attr·rhw, divided per lane; constant attributes
// are filled once and kept while the span's lanes still hold them.
template <class Fill>
void spanAttributes(const TriangleSetup& s, uint64_t used, bool wantZ, int n, QuadSpan& span, Fill&& fill) {
    const uint64_t planes = used & ~s.constMask;
    if (wantZ) fill(s.z, span.z);
    if (s.perspective) {
        // attr = (attr·rhw)/rhw per lane.
        alignas(32) float inv[ps11::kMaxSpan];
        fill(s.rhw, inv);
        for (int L = 0; L < n; ++L) inv[L] = inverseRhw(inv[L]);
        for (int k = 0; k < kAttrCount; ++k) {
            if (!((planes >> k) & 1)) continue;
            float* out = span.attr[k];
            fill(s.attr[size_t(k)], out);
            for (int L = 0; L < n; ++L) out[L] *= inv[L];
        }
    } else {
        for (int k = 0; k < kAttrCount; ++k)
            if ((planes >> k) & 1) fill(s.attr[size_t(k)], span.attr[k]);
    }
    for (int k = 0; k < kAttrCount; ++k)
        if ((planes >> k) & 1) span.constLanes[size_t(k)] = 0;
    const uint64_t consts = used & s.constMask;
    for (int k = 0; k < kAttrCount; ++k) {
        if (!((consts >> k) & 1)) continue;
        const float value = s.constValue[size_t(k)];
        int& have = span.constLanes[size_t(k)];
        if (have > 0 && std::memcmp(&span.constFill[size_t(k)], &value, sizeof value) != 0) have = 0;
        if (have < n) {
            std::fill(span.attr[k] + have, span.attr[k] + n, value);
            span.constFill[size_t(k)] = value;
            have = n;
        }
    }
}

}  // namespace

// (The same sum as fillPlane's.)
void fillPlaneRow(const Plane& p, double ox, double oy, int x0, int y, int n, float* out) {
    const float base = float(planeRowBase(p, ox, oy, y)), fdx = float(p.dx);
    for (int i = 0; i < n; ++i) out[i] = base + fdx * float(x0 + i);
}

float planeValue(const Plane& p, double ox, double oy, int x, int y) {
    const float base = float(planeRowBase(p, ox, oy, y));
    const float prod = float(p.dx) * float(x);
    return base + prod;
}

bool setupTriangle(const ScreenTriangle& tri, uint64_t used, const ClipRect& clip, TriangleSetup& s) {
    if (clip.x0 >= clip.x1 || clip.y0 >= clip.y1) return false;
    std::array<int64_t, 3> X, Y;
    for (size_t i = 0; i < 3; ++i) {
        // Snap to 1/256 pixel (round half away from zero; positions are within the guard band).
        X[i] = std::llround(tri.v[i].x * double(kOne));
        Y[i] = std::llround(tri.v[i].y * double(kOne));
    }
    for (size_t i = 0; i < 3; ++i) {
        const size_t j = (i + 1) % 3;
        s.a[i] = -(Y[j] - Y[i]);
        s.b[i] = X[j] - X[i];
        s.c[i] = -s.a[i] * X[i] - s.b[i] * Y[i];
    }
    const int64_t area = s.a[0] * X[2] + s.b[0] * Y[2] + s.c[0];
    if (area == 0) return false;
    if (area < 0)
        for (size_t i = 0; i < 3; ++i) {
            s.a[i] = -s.a[i];
            s.b[i] = -s.b[i];
            s.c[i] = -s.c[i];
        }
    // Inside is E > 0. Top-left rule: a left edge has the inside to its right (a > 0), a top edge
    // is horizontal with the inside below (a == 0, b > 0); pixel centres on them are covered.
    for (size_t i = 0; i < 3; ++i) s.t[i] = (s.a[i] > 0 || (s.a[i] == 0 && s.b[i] > 0)) ? 0 : 1;

    const int64_t yLo = std::min({Y[0], Y[1], Y[2]}), yHi = std::max({Y[0], Y[1], Y[2]});
    s.clip = clip;
    s.yMin = int(std::max<int64_t>(clip.y0, ceilDiv(yLo, kOne)));
    s.yMax = int(std::min<int64_t>(clip.y1, floorDiv(yHi, kOne) + 1));
    const int64_t xLo = std::min({X[0], X[1], X[2]}), xHi = std::max({X[0], X[1], X[2]});
    if (s.yMin >= s.yMax || ceilDiv(xLo, kOne) >= clip.x1 || floorDiv(xHi, kOne) < clip.x0) return false;

    // Attribute planes from the snapped positions.
    const double x0 = double(X[0]) / kOne, y0 = double(Y[0]) / kOne;
    const double x1 = double(X[1]) / kOne - x0, y1 = double(Y[1]) / kOne - y0;
    const double x2 = double(X[2]) / kOne - x0, y2 = double(Y[2]) / kOne - y0;
    const double det = x1 * y2 - x2 * y1;
    s.ox = x0;
    s.oy = y0;
    auto plane = [&](double a0, double a1, double a2) {
        const double d1 = a1 - a0, d2 = a2 - a0;
        return Plane{a0, (d1 * y2 - d2 * y1) / det, (d2 * x1 - d1 * x2) / det};
    };
    const ScreenVertex& v0 = tri.v[0];
    const ScreenVertex& v1 = tri.v[1];
    const ScreenVertex& v2 = tri.v[2];
    s.perspective = !(v0.rhw == v1.rhw && v1.rhw == v2.rhw);
    s.rhw = plane(v0.rhw, v1.rhw, v2.rhw);
    s.z = plane(v0.z, v1.z, v2.z);
    s.constMask = 0;
    for (int k = 0; k < kAttrCount; ++k) {
        if (!((used >> k) & 1)) continue;
        const float a0 = v0.attr[size_t(k)], a1 = v1.attr[size_t(k)], a2 = v2.attr[size_t(k)];
        if (a0 == a1 && a1 == a2) {
            // Equal at the vertices: exactly that value everywhere (no rounding of a plane).
            s.constMask |= uint64_t(1) << k;
            s.constValue[size_t(k)] = a0;
        } else if (s.perspective) {
            s.attr[size_t(k)] = plane(double(a0) * v0.rhw, double(a1) * v1.rhw, double(a2) * v2.rhw);
        } else {
            s.attr[size_t(k)] = plane(a0, a1, a2);
        }
    }
    return true;
}

bool rowCoverage(const TriangleSetup& s, int y, int& xl, int& xr) {
    if (y < s.yMin || y >= s.yMax) return false;
    int64_t lo = s.clip.x0, hi = s.clip.x1;  // [lo, hi)
    const int64_t Y = int64_t(y) * kOne;
    for (size_t i = 0; i < 3; ++i) {
        // Covered: a·256·x + k >= t with k = b·Y + c, solved exactly for the integer x.
        const int64_t k = s.b[i] * Y + s.c[i];
        const int64_t A = s.a[i] * kOne;
        if (A > 0) {
            lo = std::max(lo, ceilDiv(s.t[i] - k, A));
        } else if (A < 0) {
            hi = std::min(hi, floorDiv(k - s.t[i], -A) + 1);
        } else if (k < s.t[i]) {
            return false;
        }
        if (lo >= hi) return false;
    }
    xl = int(lo);
    xr = int(hi);
    return true;
}

bool coveredColumns(const TriangleSetup& s, int& xlo, int& xhi) {
    // Each edge's bound on a row is a quotient of n = q·d + r (0 <= r < d): lo = ceil(n / A) =
    // q + (r ≠ 0) for A > 0 with n = t − k, hi = floor(n / −A) + 1 = q + 1 for A < 0 with n = k − t.
    // From one row to the next n moves by a constant, so q and r move by its quotient and
    // remainder. (A = 0: the row is covered while k >= t.)
    struct Edge {
        int kind = 0;  // +1 bounds lo, −1 bounds hi, 0 none (A = 0)
        int64_t q = 0, r = 0, d = 1, dq = 0, dr = 0;
        int64_t k = 0, dk = 0, t = 0;  // (kind 0)
    };
    Edge e[3];
    const int64_t Y0 = int64_t(s.yMin) * kOne;
    for (size_t i = 0; i < 3; ++i) {
        Edge& g = e[i];
        const int64_t k = s.b[i] * Y0 + s.c[i], dk = s.b[i] * kOne, A = s.a[i] * kOne;
        if (A == 0) {
            g.k = k, g.dk = dk, g.t = s.t[i];
            continue;
        }
        g.kind = A > 0 ? 1 : -1;
        g.d = A > 0 ? A : -A;
        const int64_t n = A > 0 ? s.t[i] - k : k - s.t[i], dn = A > 0 ? -dk : dk;
        g.q = floorDiv(n, g.d), g.r = n - g.q * g.d;
        g.dq = floorDiv(dn, g.d), g.dr = dn - g.dq * g.d;
    }
    int64_t lo0 = s.clip.x1, hi0 = s.clip.x0;
    for (int y = s.yMin; y < s.yMax; ++y) {
        int64_t lo = s.clip.x0, hi = s.clip.x1;
        bool covered = true;
        for (Edge& g : e) {
            if (g.kind > 0) {
                lo = std::max(lo, g.q + (g.r != 0));
            } else if (g.kind < 0) {
                hi = std::min(hi, g.q + 1);
            } else {
                covered = covered && g.k >= g.t;
                g.k += g.dk;
                continue;
            }
            g.q += g.dq, g.r += g.dr;
            if (g.r >= g.d) g.r -= g.d, ++g.q;
        }
        if (covered && lo < hi) lo0 = std::min(lo0, lo), hi0 = std::max(hi0, hi);
    }
    if (lo0 >= hi0) return false;
    xlo = int(lo0), xhi = int(hi0);
    return true;
}

void rasterizeRows(const TriangleSetup& s, int y0, int y1, uint64_t used, bool wantZ, QuadSpan& span,
                   const std::function<void(QuadSpan&)>& emit) {
    const int yStart = std::max(y0, s.yMin & ~1);
    const int yEnd = std::min(y1, s.yMax);
    for (int py = yStart; py < yEnd; py += 2) {
        int l0 = 0, r0 = 0, l1 = 0, r1 = 0;
        const bool c0 = py >= y0 && rowCoverage(s, py, l0, r0);
        const bool c1 = py + 1 < y1 && rowCoverage(s, py + 1, l1, r1);
        if (!c0 && !c1) continue;
        int qx0, qx1;
        if (c0 && c1) {
            qx0 = std::min(l0, l1);
            qx1 = std::max(r0, r1);
        } else if (c0) {
            qx0 = l0, qx1 = r0;
        } else {
            qx0 = l1, qx1 = r1;
        }
        qx0 &= ~1;  // quads at even coordinates (clip rects start at >= 0)
        qx1 = (qx1 + 1) & ~1;
        constexpr int kQuadCols = ps11::kMaxSpan / 2;  // pixels per row of one span
        for (int sx = qx0; sx < qx1; sx += kQuadCols) {
            const int cols = std::min(kQuadCols, qx1 - sx);
            const int n = cols * 2;  // lanes
            span.count = n;
            for (int L = 0; L < n; ++L) span.x[L] = sx + kLanes.colInt[L];
            for (int L = 0; L < n; ++L) span.y[L] = py + kLanes.row[L];
            int liveCount = 0;
            const int ex = sx + cols;  // one past the span's last column
            if (c0 && c1 && sx >= std::max(l0, l1) && ex <= std::min(r0, r1)) {
                std::memset(span.live, 1, size_t(n));  // inside on both rows: no helper lanes
                liveCount = n;
            } else {
                // Row 0 covers [a0, b0), row 1 [a1, b1) (empty when not covered).
                const int a0 = c0 ? l0 : 0, b0 = c0 ? r0 : 0, a1 = c1 ? l1 : 0, b1 = c1 ? r1 : 0;
                for (int L = 0; L < n; ++L) {
                    const int x = span.x[L];
                    const bool in = kLanes.row[L] ? (x >= a1 && x < b1) : (x >= a0 && x < b0);
                    span.live[L] = uint8_t(in);
                    liveCount += in;
                }
            }
            span.liveCount = liveCount;
            if (liveCount == 0) continue;
            spanAttributes(s, used, wantZ, n, span,
                           [&](const Plane& p, float* out) { fillPlane(p, s.ox, s.oy, sx, py, n, out); });
            emit(span);
        }
    }
}

void rasterizeRowSpans(const TriangleSetup& s, int y0, int y1, uint64_t used, bool wantZ, QuadSpan& span,
                       const std::function<void(QuadSpan&)>& emit) {
    const int yStart = std::max(y0, s.yMin), yEnd = std::min(y1, s.yMax);
    for (int y = yStart; y < yEnd; ++y) {
        int xl = 0, xr = 0;
        if (!rowCoverage(s, y, xl, xr)) continue;
        for (int x = xl; x < xr; x += ps11::kMaxSpan) {
            const int n = std::min(ps11::kMaxSpan, xr - x);
            span.count = span.liveCount = n;
            for (int L = 0; L < n; ++L) span.x[L] = x + L, span.y[L] = y;
            std::memset(span.live, 1, size_t(n));
            spanAttributes(s, used, wantZ, n, span,
                           [&](const Plane& p, float* out) { fillPlaneRow(p, s.ox, s.oy, x, y, n, out); });
            emit(span);
        }
    }
}

}  // namespace emu
