// Vertex processing of DrawPrimitiveUP: FVF layouts, the fixed-function transform (World · View ·
// Projection, row vectors as D3D9), homogeneous clipping, the viewport, XYZRHW vertices,
// texture-coordinate routing and transforms, and triangle assembly with culling and flat shading.
#include "emu/vertex.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

namespace emu {

namespace {

constexpr DWORD kKnownFvfBits = D3DFVF_POSITION_MASK | D3DFVF_NORMAL | D3DFVF_PSIZE | D3DFVF_DIFFUSE | D3DFVF_SPECULAR |
                                D3DFVF_TEXCOUNT_MASK | 0xFFFF0000u;

// Clip-space guard band: |x|, |y| <= kClipGuard·w. With viewports of at most 16384 pixels the
// screen coordinates stay well inside kGuardBand.
constexpr double kClipGuard = 32;
// Smallest w kept: vertices at w -> 0 would project to infinity.
constexpr double kMinW = 1e-7;

// D3D transforms row vectors (v' = v·M, M[row][column]); GLM multiplies column vectors, so a
// D3D matrix goes in as its transpose: GLM column i holds D3D row i, and v·M is toMat(M) * v.
// Products keep D3D's order: (W·V)·P is toMat(P) * (toMat(V) * toMat(W)). Double precision.
glm::dmat4 toMat(const D3DMATRIX& m) {
    glm::dmat4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r[i][j] = m.m[i][j];
    return r;
}

float readFloat(const uint8_t* p) {
    float f;
    std::memcpy(&f, p, 4);
    return f;
}

void colorToAttr(DWORD c, float* out) {
    out[0] = float((c >> 16) & 0xff) / 255.0f;
    out[1] = float((c >> 8) & 0xff) / 255.0f;
    out[2] = float(c & 0xff) / 255.0f;
    out[3] = float((c >> 24) & 0xff) / 255.0f;
}

// A vertex in homogeneous clip space (untransformed path) or in screen space with a
// perspective-correct representation (XYZRHW path), with its attributes.
struct ClipVertex {
    std::array<double, 4> pos{};  // x y z w
    std::array<float, kAttrCount> attr{};
};

// Per-draw constants of vertex processing.
struct Pipeline {
    const VertexLayout* layout = nullptr;
    uint64_t usedAttrs = 0;
    glm::dmat4 wvp{1.0};
    std::array<int, kMaxTexSets> slotSet{};    // vertex set each slot reads (-1: none, defaults)
    std::array<int, kMaxTexSets> slotCount{};  // texture transform output count (0 = no transform)
    std::array<glm::dmat4, kMaxTexSets> texMat{};
    double vpX = 0, vpY = 0, vpW = 0, vpH = 0, minZ = 0, maxZ = 1;
    D3DCULL cull = D3DCULL_CCW;
    bool flat = false;
};

void readVertex(const Pipeline& p, const uint8_t* v, ClipVertex& out) {
    const VertexLayout& L = *p.layout;
    const float x = readFloat(v), y = readFloat(v + 4), z = readFloat(v + 8);
    if (L.pretransformed) {
        out.pos = {x, y, z, double(readFloat(v + 12))};  // w slot holds rhw here
    } else {
        const glm::dvec4 c = p.wvp * glm::dvec4(x, y, z, 1.0);
        for (int j = 0; j < 4; ++j) out.pos[size_t(j)] = c[j];
    }
    out.attr.fill(0.0f);
    if (L.hasDiffuse) {
        DWORD c;
        std::memcpy(&c, v + L.diffuseOffset, 4);
        colorToAttr(c, &out.attr[kAttrDiffuse]);
    } else {
        for (int c = 0; c < 4; ++c) out.attr[size_t(kAttrDiffuse + c)] = 1.0f;  // D3D9 default 0xFFFFFFFF
    }
    if (L.hasSpecular) {
        DWORD c;
        std::memcpy(&c, v + L.specularOffset, 4);
        colorToAttr(c, &out.attr[kAttrSpecular]);
    } else {
        // Specular defaults to 0; its alpha is the fog factor, which without specular stays 1 (no fog).
        out.attr[kAttrSpecular + 3] = 1.0f;
    }
    for (int slot = 0; slot < kMaxTexSets; ++slot) {
        if (!((p.usedAttrs >> attrTex(slot, 0)) & 0xF)) continue;
        // D3D9 fills missing components with (0, 0, 0, 1); the texture transform instead sees a 1
        // right after the last given component (u, 1, 0, 0), (u, v, 1, 0), (u, v, w, 1).
        std::array<double, 4> in{0, 0, 0, 1};
        const int set = p.slotSet[size_t(slot)];
        int n = 0;
        if (set >= 0) {
            n = L.texSize[size_t(set)];
            for (int c = 0; c < n; ++c) in[size_t(c)] = readFloat(v + L.texOffset[size_t(set)] + 4 * c);
        }
        std::array<double, 4> t = in;
        const int count = p.slotCount[size_t(slot)];
        if (count > 0) {
            std::array<double, 4> src{0, 0, 0, 0};
            for (int c = 0; c < n; ++c) src[size_t(c)] = in[size_t(c)];
            if (n < 4) src[size_t(n)] = 1;
            if (set < 0) src = {0, 0, 0, 1};
            const glm::dvec4 r = p.texMat[size_t(slot)] * glm::dvec4(src[0], src[1], src[2], src[3]);
            for (int j = 0; j < 4; ++j) t[size_t(j)] = r[j];
            for (int c = count; c < 4; ++c) t[size_t(c)] = c == 3 ? 1.0 : 0.0;
        }
        for (int c = 0; c < 4; ++c) out.attr[size_t(attrTex(slot, c))] = float(t[size_t(c)]);
    }
}

// Flat shading: the first vertex's colours on the whole triangle; the fog factor (specular
// alpha) is still interpolated (D3D9 "Triangle Interpolation").
void applyFlat(ClipVertex* tri[3], const ClipVertex& provoking, ClipVertex out[3]) {
    for (int i = 0; i < 3; ++i) {
        out[i] = *tri[i];
        for (int c = 0; c < 4; ++c) out[i].attr[size_t(kAttrDiffuse + c)] = provoking.attr[size_t(kAttrDiffuse + c)];
        for (int c = 0; c < 3; ++c) out[i].attr[size_t(kAttrSpecular + c)] = provoking.attr[size_t(kAttrSpecular + c)];
    }
}

template <class F>
void lerpVertex(const ClipVertex& a, const ClipVertex& b, double t, uint64_t used, ClipVertex& out, F&& attrLerp) {
    for (size_t j = 0; j < 4; ++j) out.pos[j] = a.pos[j] + (b.pos[j] - a.pos[j]) * t;
    for (int k = 0; k < kAttrCount; ++k) out.attr[size_t(k)] = ((used >> k) & 1) ? attrLerp(k, t) : 0.0f;
}

// Sutherland–Hodgman against dist(v) >= 0, attributes interpolated linearly in the space the
// distance is linear in (clip space: perspective-correct by construction).
template <class Dist, class Lerp>
void clipPolygon(std::vector<ClipVertex>& poly, std::vector<ClipVertex>& tmp, Dist&& dist, Lerp&& lerp) {
    tmp.clear();
    const size_t n = poly.size();
    for (size_t i = 0; i < n; ++i) {
        const ClipVertex& a = poly[i];
        const ClipVertex& b = poly[(i + 1) % n];
        const double da = dist(a), db = dist(b);
        if (da >= 0) tmp.push_back(a);
        if ((da >= 0) != (db >= 0)) {
            const double t = da / (da - db);
            ClipVertex v;
            lerp(a, b, t, v);
            tmp.push_back(v);
        }
    }
    poly.swap(tmp);
}

bool finite4(const std::array<double, 4>& p) {
    return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) && std::isfinite(p[3]);
}

class Processor {
public:
    Processor(const Pipeline& p, std::vector<ScreenTriangle>& out, VertexStats& stats)
        : m_p(p), m_out(out), m_stats(stats) {}

    void triangle(const ClipVertex& a, const ClipVertex& b, const ClipVertex& c, const ClipVertex& provoking) {
        ++m_stats.triangles;
        const ClipVertex* in[3] = {&a, &b, &c};
        ClipVertex flat[3];
        if (m_p.flat) {
            ClipVertex* t[3] = {const_cast<ClipVertex*>(&a), const_cast<ClipVertex*>(&b), const_cast<ClipVertex*>(&c)};
            applyFlat(t, provoking, flat);
            for (int i = 0; i < 3; ++i) in[i] = &flat[i];
        }
        for (int i = 0; i < 3; ++i)
            if (!finite4(in[i]->pos)) {
                ++m_stats.clipped;
                return;
            }
        m_poly.assign({*in[0], *in[1], *in[2]});
        if (m_p.layout->pretransformed ? !screenPolygon() : !clipSpacePolygon()) {
            ++m_stats.clipped;
            return;
        }
        emit();
    }

private:
    // Untransformed: clip in homogeneous space, then divide and map through the viewport.
    bool clipSpacePolygon() {
        const uint64_t used = m_p.usedAttrs;
        auto lerp = [used](const ClipVertex& a, const ClipVertex& b, double t, ClipVertex& o) {
            lerpVertex(a, b, t, used, o, [&](int k, double tt) {
                return float(double(a.attr[size_t(k)]) + (double(b.attr[size_t(k)]) - a.attr[size_t(k)]) * tt);
            });
        };
        const auto planes = std::array<std::array<double, 5>, 7>{{
            // dist = a·x + b·y + c·z + d·w + e
            {0, 0, 0, 1, -kMinW},       // w > 0
            {0, 0, 1, 0, 0},            // near: z >= 0
            {0, 0, -1, 1, 0},           // far: z <= w
            {-1, 0, 0, kClipGuard, 0},  // guard band
            {1, 0, 0, kClipGuard, 0},
            {0, -1, 0, kClipGuard, 0},
            {0, 1, 0, kClipGuard, 0},
        }};
        for (const auto& pl : planes) {
            auto dist = [&pl](const ClipVertex& v) {
                return pl[0] * v.pos[0] + pl[1] * v.pos[1] + pl[2] * v.pos[2] + pl[3] * v.pos[3] + pl[4];
            };
            bool allIn = true;
            for (const ClipVertex& v : m_poly) allIn = allIn && dist(v) >= 0;
            if (allIn) continue;
            clipPolygon(m_poly, m_tmp, dist, lerp);
            if (m_poly.size() < 3) return false;
        }
        m_screen.clear();
        for (const ClipVertex& v : m_poly) {
            ScreenVertex s;
            const double w = v.pos[3];
            const double iw = 1.0 / w;
            s.x = m_p.vpX + (1.0 + v.pos[0] * iw) * m_p.vpW * 0.5;
            s.y = m_p.vpY + (1.0 - v.pos[1] * iw) * m_p.vpH * 0.5;
            s.z = float(m_p.minZ + v.pos[2] * iw * (m_p.maxZ - m_p.minZ));
            s.rhw = float(iw);
            s.attr = v.attr;
            m_screen.push_back(s);
        }
        return true;
    }

    // XYZRHW: positions are screen coordinates; only the guard band clips, in screen space, with
    // attributes interpolated perspective-correctly (attr·rhw and rhw are linear on the screen).
    bool screenPolygon() {
        for (const ClipVertex& v : m_poly)
            if (!(v.pos[3] > 0)) return false;  // rhw <= 0 (or NaN): undefined in D3D9, dropped
        const uint64_t used = m_p.usedAttrs;
        auto lerp = [used](const ClipVertex& a, const ClipVertex& b, double t, ClipVertex& o) {
            const double ra = a.pos[3], rb = b.pos[3];
            const double r = ra + (rb - ra) * t;
            lerpVertex(a, b, t, used, o, [&](int k, double tt) {
                const double qa = a.attr[size_t(k)] * ra, qb = b.attr[size_t(k)] * rb;
                return float((qa + (qb - qa) * tt) / r);
            });
        };
        const double g = kGuardBand;
        const auto planes = std::array<std::array<double, 3>, 4>{{{-1, 0, g}, {1, 0, g}, {0, -1, g}, {0, 1, g}}};
        for (const auto& pl : planes) {
            auto dist = [&pl](const ClipVertex& v) { return pl[0] * v.pos[0] + pl[1] * v.pos[1] + pl[2]; };
            bool allIn = true;
            for (const ClipVertex& v : m_poly) allIn = allIn && dist(v) >= 0;
            if (allIn) continue;
            clipPolygon(m_poly, m_tmp, dist, lerp);
            if (m_poly.size() < 3) return false;
        }
        m_screen.clear();
        for (const ClipVertex& v : m_poly) {
            ScreenVertex s;
            s.x = v.pos[0];
            s.y = v.pos[1];
            s.z = float(v.pos[2]);
            s.rhw = float(v.pos[3]);
            s.attr = v.attr;
            m_screen.push_back(s);
        }
        return true;
    }

    // Culling by the screen-space winding of the (clipped) polygon, then a fan of triangles.
    void emit() {
        double area2 = 0;  // > 0: clockwise on the screen (y down)
        const size_t n = m_screen.size();
        for (size_t i = 0; i < n; ++i) {
            const ScreenVertex& a = m_screen[i];
            const ScreenVertex& b = m_screen[(i + 1) % n];
            area2 += a.x * b.y - b.x * a.y;
        }
        if (culledByWinding(m_p.cull, area2)) {
            ++m_stats.culled;
            return;
        }
        for (size_t i = 1; i + 1 < n; ++i) m_out.push_back(ScreenTriangle{{m_screen[0], m_screen[i], m_screen[i + 1]}});
    }

    const Pipeline& m_p;
    std::vector<ScreenTriangle>& m_out;
    VertexStats& m_stats;
    std::vector<ClipVertex> m_poly, m_tmp;
    std::vector<ScreenVertex> m_screen;
};

}  // namespace

std::optional<VertexLayout> parseFvf(DWORD fvf, std::string& error) {
    VertexLayout L;
    if (fvf & ~kKnownFvfBits) {
        error = "FVF bits 0x" +
                [](DWORD v) {
                    char b[16];
                    std::snprintf(b, sizeof b, "%x", unsigned(v));
                    return std::string(b);
                }(fvf & ~kKnownFvfBits) +
                " are not taken (blend weights, D3DFVF_LASTBETA_*)";
        return std::nullopt;
    }
    const DWORD pos = fvf & D3DFVF_POSITION_MASK;
    if (pos == 0) {
        error = "FVF has no position (D3DFVF_XYZ or D3DFVF_XYZRHW)";
        return std::nullopt;
    }
    if (pos != D3DFVF_XYZ && pos != D3DFVF_XYZRHW) {
        error = "FVF position type is not taken (only D3DFVF_XYZ and D3DFVF_XYZRHW; no XYZW or blend weights)";
        return std::nullopt;
    }
    L.pretransformed = pos == D3DFVF_XYZRHW;
    uint32_t off = L.pretransformed ? 16 : 12;
    if (fvf & D3DFVF_NORMAL) {
        if (L.pretransformed) {
            error = "D3DFVF_NORMAL with D3DFVF_XYZRHW (pre-transformed vertices have no normal)";
            return std::nullopt;
        }
        off += 12;
    }
    if (fvf & D3DFVF_PSIZE) off += 4;
    if (fvf & D3DFVF_DIFFUSE) {
        L.hasDiffuse = true;
        L.diffuseOffset = off;
        off += 4;
    }
    if (fvf & D3DFVF_SPECULAR) {
        L.hasSpecular = true;
        L.specularOffset = off;
        off += 4;
    }
    const DWORD count = (fvf & D3DFVF_TEXCOUNT_MASK) >> D3DFVF_TEXCOUNT_SHIFT;
    if (count > DWORD(kMaxTexSets)) {
        error = "FVF texture coordinate count " + std::to_string(count) + " beyond 8";
        return std::nullopt;
    }
    L.texCount = int(count);
    for (int i = 0; i < L.texCount; ++i) {
        static constexpr uint8_t kSizes[4] = {2, 3, 4, 1};  // D3DFVF_TEXTUREFORMAT2, 3, 4, 1
        L.texSize[size_t(i)] = kSizes[(fvf >> (16 + 2 * i)) & 3];
        L.texOffset[size_t(i)] = off;
        off += 4u * L.texSize[size_t(i)];
    }
    L.size = off;
    return L;
}

uint64_t vertexCountOf(D3DPRIMITIVETYPE type, uint64_t n) {
    switch (type) {
        case D3DPT_TRIANGLELIST:
            return 3 * n;
        case D3DPT_TRIANGLESTRIP:
        case D3DPT_TRIANGLEFAN:
            return n + 2;
        case D3DPT_POINTLIST:
            return n;
        case D3DPT_LINELIST:
            return 2 * n;
        case D3DPT_LINESTRIP:
            return n + 1;
    }
    return 0;
}

void processTriangles(const DeviceState& state, const VertexSetup& setup, D3DPRIMITIVETYPE type, uint32_t first,
                      uint32_t count, const uint8_t* data, uint32_t stride, std::vector<ScreenTriangle>& out,
                      VertexStats* statsOut) {
    Pipeline p;
    p.layout = setup.layout;
    p.usedAttrs = setup.usedAttrs;
    const VertexLayout& L = *setup.layout;
    p.wvp = toMat(state.projection) * (toMat(state.view) * toMat(state.world));
    for (int slot = 0; slot < kMaxTexSets; ++slot) {
        const DWORD index = state.stageState(slot, D3DTSS_TEXCOORDINDEX) & 0xFFFF;
        p.slotSet[size_t(slot)] = index < DWORD(L.texCount) ? int(index) : -1;
        // Texture transforms apply to untransformed vertices only; COUNT1 is ignored (Wine's
        // tests of native D3D9); PROJECTED is the executor's business (StageState).
        const DWORD flags = state.stageState(slot, D3DTSS_TEXTURETRANSFORMFLAGS) & 0xFF;
        p.slotCount[size_t(slot)] = (!L.pretransformed && flags >= 2 && flags <= 4) ? int(flags) : 0;
        p.texMat[size_t(slot)] = toMat(state.texture[size_t(slot)]);
    }
    p.vpX = state.viewport.X;
    p.vpY = state.viewport.Y;
    p.vpW = state.viewport.Width;
    p.vpH = state.viewport.Height;
    p.minZ = state.viewport.MinZ;
    p.maxZ = state.viewport.MaxZ;
    p.cull = D3DCULL(state.renderState(D3DRS_CULLMODE));
    p.flat = state.renderState(D3DRS_SHADEMODE) == D3DSHADE_FLAT;

    VertexStats stats;
    Processor proc(p, out, stats);
    ClipVertex v[3];
    auto read = [&](uint64_t index, ClipVertex& o) { readVertex(p, data + index * uint64_t(stride), o); };
    for (uint64_t t = first; t < uint64_t(first) + count; ++t) {
        switch (type) {
            case D3DPT_TRIANGLELIST:
                for (int k = 0; k < 3; ++k) read(3 * t + uint64_t(k), v[k]);
                proc.triangle(v[0], v[1], v[2], v[0]);
                break;
            case D3DPT_TRIANGLESTRIP:
                // D3D9: odd triangles are (v[i], v[i+2], v[i+1]) so that all keep the winding;
                // the first vertex (flat shading) is v[i].
                for (int k = 0; k < 3; ++k) read(t + uint64_t(k), v[k]);
                if (t & 1)
                    proc.triangle(v[0], v[2], v[1], v[0]);
                else
                    proc.triangle(v[0], v[1], v[2], v[0]);
                break;
            case D3DPT_TRIANGLEFAN:
                // D3D9: (v[i+1], v[i+2], v[0]); its first vertex v[i+1] shades a flat triangle.
                read(t + 1, v[0]);
                read(t + 2, v[1]);
                read(0, v[2]);
                proc.triangle(v[0], v[1], v[2], v[0]);
                break;
            default:
                return;
        }
    }
    if (statsOut) {
        statsOut->triangles += stats.triangles;
        statsOut->culled += stats.culled;
        statsOut->clipped += stats.clipped;
    }
}

}  // namespace emu
