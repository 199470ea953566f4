// The toolkit of the built-in scenes (glare/scene.cpp): vertices and colours, deterministic
// noise, per-vertex lighting on the CPU, world-space meshes, and SceneBase, which sets up the
// frame, draws meshes as painter's layers (clipped and projected here, drawn as XYZRHW
// triangles) or through the device's transforms with depth, and puts the caller's device state
// back (emu::Device::applyState).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "glare/scene.h"

namespace glare::scene_kit {

using namespace emu;

constexpr float kPi = 3.14159265358979f;

// ---- vertices, colours, deterministic noise ----

struct Vertex {
    float x, y, z;
    DWORD color;
};
constexpr DWORD kVertexFvf = D3DFVF_XYZ | D3DFVF_DIFFUSE;

struct ScreenVertex {
    float x, y, z, rhw;
    DWORD color;
};
constexpr DWORD kScreenFvf = D3DFVF_XYZRHW | D3DFVF_DIFFUSE;

inline DWORD toByte(float v) {
    if (!(v > 0.0f)) return 0;  // also NaN
    if (v >= 1.0f) return 255;
    return DWORD(v * 255.0f + 0.5f);
}

// A D3DCOLOR: rgb in [0, 1] (clamped), alpha 255 when the surface glows, else 0.
inline DWORD packColor(glm::vec3 rgb, bool glow) {
    return (glow ? 0xFF000000u : 0u) | toByte(rgb.r) << 16 | toByte(rgb.g) << 8 | toByte(rgb.b);
}

// Integer hash (a fixed mixing function: the same value on every machine).
inline uint32_t mix32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// A deterministic pseudo-random number in [0, 1) for the integers (a, b, c).
inline float noise(uint32_t a, uint32_t b = 0, uint32_t c = 0) {
    const uint32_t h = mix32(a * 0x9E3779B1u ^ mix32(b * 0x85EBCA77u ^ mix32(c + 0x27D4EB2Fu)));
    return float(h >> 8) * (1.0f / 16777216.0f);
}

inline float smoothstep01(float t) {
    t = std::clamp(t, 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

// ---- lighting (per vertex, on the CPU) ----

struct PointLight {
    glm::vec3 position, color;
    float range;  // distance at which the light falls to half
};

struct Lighting {
    glm::vec3 ambient{0.1f};
    glm::vec3 sunDirection{0.0f, -1.0f, 0.0f};  // the direction the light travels (normalised)
    glm::vec3 sunColor{0.0f};
    std::vector<PointLight> points;

    // Lambert: albedo · (ambient + sun · max(0, n·l) + Σ point · max(0, n·l) · r²/(r² + d²)).
    glm::vec3 shade(glm::vec3 albedo, glm::vec3 p, glm::vec3 n) const {
        glm::vec3 light = ambient + sunColor * std::max(0.0f, glm::dot(n, -sunDirection));
        for (const PointLight& pl : points) {
            const glm::vec3 d = pl.position - p;
            const float dist2 = glm::dot(d, d);
            if (dist2 <= 1e-12f) continue;
            const float lambert = std::max(0.0f, glm::dot(n, d) / std::sqrt(dist2));
            light += pl.color * lambert * (pl.range * pl.range / (pl.range * pl.range + dist2));
        }
        return albedo * light;
    }
};

// What a face is made of: its albedo and the lighting it receives.
struct Surface {
    glm::vec3 albedo;
    const Lighting* lighting;
};

// Every face alike.
inline std::function<Surface(glm::vec3, glm::vec3)> uniform(glm::vec3 albedo, const Lighting& lighting) {
    return [albedo, l = &lighting](glm::vec3, glm::vec3) { return Surface{albedo, l}; };
}

// ---- meshes: world-space triangle lists ----

class Mesh {
public:
    std::vector<Vertex> vertices;

    // A triangle seen from the side `facing` points to: the winding is chosen so that D3DCULL_CCW
    // keeps it from there (D3D's left-handed space: the front face's cross(b − a, c − a) points
    // towards the viewer).
    void triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, DWORD ca, DWORD cb, DWORD cc, glm::vec3 facing) {
        if (glm::dot(glm::cross(b - a, c - a), facing) < 0.0f) {
            std::swap(b, c);
            std::swap(cb, cc);
        }
        vertices.push_back({a.x, a.y, a.z, ca});
        vertices.push_back({b.x, b.y, b.z, cb});
        vertices.push_back({c.x, c.y, c.z, cc});
    }

    // A flat quad p0 p1 p2 p3 (in order around it) of one colour.
    void flatQuad(const std::array<glm::vec3, 4>& p, glm::vec3 normal, DWORD color) {
        triangle(p[0], p[1], p[2], color, color, color, normal);
        triangle(p[0], p[2], p[3], color, color, color, normal);
    }

    // A planar quad p0 p1 p2 p3 (in order around it) split into nu × nv cells and lit per vertex.
    void litQuad(const std::array<glm::vec3, 4>& p, glm::vec3 normal, glm::vec3 albedo, const Lighting& lighting,
                 int nu, int nv) {
        nu = std::max(nu, 1);
        nv = std::max(nv, 1);
        auto at = [&](int i, int j) {
            const float u = float(i) / float(nu), v = float(j) / float(nv);
            return glm::mix(glm::mix(p[0], p[1], u), glm::mix(p[3], p[2], u), v);
        };
        std::vector<glm::vec3> pos;
        std::vector<DWORD> col;
        for (int j = 0; j <= nv; ++j)
            for (int i = 0; i <= nu; ++i) {
                pos.push_back(at(i, j));
                col.push_back(packColor(lighting.shade(albedo, pos.back(), normal), false));
            }
        const int row = nu + 1;
        for (int j = 0; j < nv; ++j)
            for (int i = 0; i < nu; ++i) {
                const int a = j * row + i, b = a + 1, c = a + row + 1, d = a + row;
                triangle(pos[size_t(a)], pos[size_t(b)], pos[size_t(c)], col[size_t(a)], col[size_t(b)],
                         col[size_t(c)], normal);
                triangle(pos[size_t(a)], pos[size_t(c)], pos[size_t(d)], col[size_t(a)], col[size_t(c)],
                         col[size_t(d)], normal);
            }
    }

    // An axis-aligned box lit per vertex, each face split into cells of about `cell` units;
    // `pick` chooses each face's albedo and lighting from its centre and outward normal. No
    // bottom face when `bottom` is false.
    void litBox(glm::vec3 lo, glm::vec3 hi, float cell, const std::function<Surface(glm::vec3, glm::vec3)>& pick,
                bool bottom = true) {
        const glm::vec3 size = hi - lo;
        auto cells = [&](float extent) { return std::clamp(int(std::ceil(extent / cell - 1e-4f)), 1, 16); };
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                if (axis == 1 && side == 0 && !bottom) continue;
                glm::vec3 n(0.0f);
                n[axis] = side ? 1.0f : -1.0f;
                const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
                const float w = side ? hi[axis] : lo[axis];
                std::array<glm::vec3, 4> p;
                for (int k = 0; k < 4; ++k) {
                    glm::vec3 q;
                    q[axis] = w;
                    q[ua] = (k == 1 || k == 2) ? hi[ua] : lo[ua];
                    q[va] = (k >= 2) ? hi[va] : lo[va];
                    p[size_t(k)] = q;
                }
                const Surface surface = pick((p[0] + p[2]) * 0.5f, n);
                litQuad(p, n, surface.albedo, *surface.lighting, cells(size[ua]), cells(size[va]));
            }
    }

    // Emissive solids: flat faces of `rgb` darkened slightly away from `toLight` (so the shape
    // reads), alpha 255. `model` places them.
    void emissiveFace(const glm::mat4& model, std::initializer_list<glm::vec3> corners, glm::vec3 rgb,
                      glm::vec3 toLight) {
        std::vector<glm::vec3> p;
        for (const glm::vec3& c : corners) p.push_back(glm::vec3(model * glm::vec4(c, 1.0f)));
        glm::vec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
        const float len = glm::length(n);
        if (len <= 0.0f) return;
        n /= len;
        // Outward: away from the solid's centre (the model's origin).
        const glm::vec3 origin(model * glm::vec4(0, 0, 0, 1));
        if (glm::dot(n, p[0] - origin) < 0.0f) n = -n;
        const DWORD c = packColor(rgb * (0.78f + 0.22f * std::max(0.0f, glm::dot(n, toLight))), true);
        for (size_t i = 1; i + 1 < p.size(); ++i) triangle(p[0], p[i], p[i + 1], c, c, c, n);
    }

    void emissiveCube(const glm::mat4& model, float half, glm::vec3 rgb, glm::vec3 toLight) {
        const float h = half;
        for (int axis = 0; axis < 3; ++axis)
            for (float s : {-h, h}) {
                std::array<glm::vec3, 4> q;
                const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
                for (int k = 0; k < 4; ++k) {
                    q[size_t(k)][axis] = s;
                    q[size_t(k)][ua] = (k == 1 || k == 2) ? h : -h;
                    q[size_t(k)][va] = (k >= 2) ? h : -h;
                }
                emissiveFace(model, {q[0], q[1], q[2], q[3]}, rgb, toLight);
            }
    }

    void emissiveOctahedron(const glm::mat4& model, float r, glm::vec3 rgb, glm::vec3 toLight) {
        const glm::vec3 x(r, 0, 0), y(0, r, 0), z(0, 0, r);
        for (float sx : {-1.0f, 1.0f})
            for (float sy : {-1.0f, 1.0f})
                for (float sz : {-1.0f, 1.0f}) emissiveFace(model, {sx * x, sy * y, sz * z}, rgb, toLight);
    }

    // A prism of `sides` sides, radius r, from y = −h/2 to h/2.
    void emissivePrism(const glm::mat4& model, float r, float h, int sides, glm::vec3 rgb, glm::vec3 toLight) {
        std::vector<glm::vec3> top, bottom;
        for (int i = 0; i < sides; ++i) {
            const float a = 2.0f * kPi * float(i) / float(sides);
            top.push_back({r * std::cos(a), h / 2, r * std::sin(a)});
            bottom.push_back({r * std::cos(a), -h / 2, r * std::sin(a)});
        }
        for (int i = 0; i < sides; ++i) {
            const size_t a = size_t(i), b = size_t((i + 1) % sides);
            emissiveFace(model, {bottom[a], bottom[b], top[b], top[a]}, rgb, toLight);
        }
        for (int i = 1; i + 1 < sides; ++i) {
            emissiveFace(model, {top[0], top[size_t(i)], top[size_t(i) + 1]}, rgb, toLight);
            emissiveFace(model, {bottom[0], bottom[size_t(i)], bottom[size_t(i) + 1]}, rgb, toLight);
        }
    }

    // A UV sphere lit per vertex (normals radial).
    void litSphere(glm::vec3 centre, float r, int slices, int stacks, glm::vec3 albedo, const Lighting& lighting) {
        auto point = [&](int i, int j) {
            const float phi = kPi * float(j) / float(stacks) - kPi / 2;  // −90° … 90°
            const float theta = 2.0f * kPi * float(i) / float(slices);
            return glm::vec3(std::cos(phi) * std::cos(theta), std::sin(phi), std::cos(phi) * std::sin(theta));
        };
        auto color = [&](glm::vec3 n) { return packColor(lighting.shade(albedo, centre + r * n, n), false); };
        for (int j = 0; j < stacks; ++j)
            for (int i = 0; i < slices; ++i) {
                const glm::vec3 n00 = point(i, j), n10 = point(i + 1, j), n11 = point(i + 1, j + 1),
                                n01 = point(i, j + 1);
                const glm::vec3 facing = glm::normalize(n00 + n10 + n11 + n01);
                if (j > 0)
                    triangle(centre + r * n00, centre + r * n10, centre + r * n11, color(n00), color(n10), color(n11),
                             facing);
                if (j + 1 < stacks)
                    triangle(centre + r * n00, centre + r * n11, centre + r * n01, color(n00), color(n11), color(n01),
                             facing);
            }
    }

    // A thin emissive strip from a to b in the plane z = `z` (facing −z), `width` wide,
    // extended by half its width at both ends so joints of a polyline close.
    void strip(glm::vec2 a, glm::vec2 b, float z, float width, DWORD color) {
        glm::vec2 d = b - a;
        const float len = glm::length(d);
        if (len <= 0.0f) return;
        d /= len;
        const glm::vec2 e = d * (width / 2), n = glm::vec2(-d.y, d.x) * (width / 2);
        auto p = [&](glm::vec2 q) { return glm::vec3(q, z); };
        flatQuad({p(a - e - n), p(b + e - n), p(b + e + n), p(a - e + n)}, {0, 0, -1}, color);
    }
};

// A disc of radius r at `centre` facing `towards`, one colour.
inline void disc(Mesh& mesh, glm::vec3 centre, glm::vec3 towards, float r, DWORD color, int sides = 32) {
    const glm::vec3 n = glm::normalize(towards);
    const glm::vec3 helper = std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 u = glm::normalize(glm::cross(helper, n)), v = glm::cross(n, u);
    for (int i = 0; i < sides; ++i) {
        const float a0 = 2.0f * kPi * float(i) / float(sides), a1 = 2.0f * kPi * float(i + 1) / float(sides);
        mesh.triangle(centre, centre + r * (std::cos(a0) * u + std::sin(a0) * v),
                      centre + r * (std::cos(a1) * u + std::sin(a1) * v), color, color, color, n);
    }
}

inline D3DMATRIX toD3D(const glm::mat4& m) {
    // D3D transforms row vectors (v·M, m[row][col]); GLM's matrices act on column vectors and are
    // stored column by column, so D3D's m[i][j] is GLM's m[i][j] (column i, row j): the same floats.
    D3DMATRIX d;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) d.m[i][j] = m[i][j];
    return d;
}

// ---- the frame: device setup, the caller's state put back, drawing helpers ----

class SceneBase : public Scene {
public:
    explicit SceneBase(std::string_view name) : m_name(name) {}

    bool render(Device& device, Handle target, int frame, int frameCount, std::string& error) final {
        m_device = &device;
        m_error = &error;
        error.clear();
        if (frameCount < 1) return fail("frameCount must be at least 1 (got " + std::to_string(frameCount) + ")");
        if (frame < 0 || frame >= frameCount)
            return fail("frame " + std::to_string(frame) + " out of range 0.." + std::to_string(frameCount - 1));
        D3DSURFACE_DESC desc;
        if (!check(device.GetDesc(target, &desc), "GetDesc")) return false;
        if (desc.Format != D3DFMT_A8R8G8B8 || !(desc.Usage & D3DUSAGE_RENDERTARGET))
            return fail("the target must be an A8R8G8B8 render target (format " + std::to_string(desc.Format) +
                        ", usage " + std::to_string(desc.Usage) + ")");
        if (!depthSurface(device, desc.Width, desc.Height)) return false;

        const DeviceState saved = device.state();
        m_width = desc.Width;
        m_height = desc.Height;
        bool ok = setUp(target) && draw(frame, frameCount);
        // Put back the caller's state, even after a failure (the first failure is reported).
        std::string drawError = error;
        const bool restored = check(device.applyState(saved), "applyState");
        if (!ok) error = drawError;
        return ok && restored;
    }

protected:
    // Draws the frame (the target, depth buffer and states are set and cleared).
    virtual bool draw(int frame, int frameCount) = 0;
    virtual D3DCOLOR clearColor() const { return 0; }

    UINT width() const { return m_width; }
    UINT height() const { return m_height; }
    float aspect() const { return float(m_width) / float(m_height); }

    bool fail(const std::string& message) {
        *m_error = "scene " + std::string(m_name) + ": " + message;
        return false;
    }
    bool check(HRESULT hr, const char* call) {
        if (hr == D3D_OK) return true;
        return fail(std::string("Device::") + call + " failed: " + m_device->lastError().message);
    }

    // A left-handed camera at `eye` looking at `at` (y up), vertical field of view in degrees,
    // depth range [0, 1] (D3D).
    bool camera(glm::vec3 eye, glm::vec3 at, float fovDeg, float zNear, float zFar) {
        m_eye = eye;
        m_at = at;
        m_view = glm::lookAtLH(eye, at, glm::vec3(0, 1, 0));
        m_proj = glm::perspectiveLH_ZO(fovDeg * kPi / 180.0f, aspect(), zNear, zFar);
        const D3DMATRIX world = toD3D(glm::mat4(1.0f)), view = toD3D(m_view), proj = toD3D(m_proj);
        return check(m_device->SetTransform(D3DTS_WORLD, &world), "SetTransform") &&
               check(m_device->SetTransform(D3DTS_VIEW, &view), "SetTransform") &&
               check(m_device->SetTransform(D3DTS_PROJECTION, &proj), "SetTransform");
    }

    // Projects a world point as the device does (row vectors through View · Projection, then the
    // viewport): screen x, y (pixel centres at integers), z in [0, 1] and rhw. False when it lies
    // behind the near plane or (unless `anyDepth`) beyond the far plane.
    bool project(glm::vec3 p, glm::dvec4& screen, bool anyDepth = false) const {
        const glm::dvec4 c = glm::dmat4(m_proj) * (glm::dmat4(m_view) * glm::dvec4(glm::dvec3(p), 1.0));
        if (!(c.w > 1e-6) || c.z < 0.0 || (!anyDepth && c.z > c.w)) return false;
        screen = {(1.0 + c.x / c.w) * double(m_width) / 2.0, (1.0 - c.y / c.w) * double(m_height) / 2.0, c.z / c.w,
                  1.0 / c.w};
        return true;
    }

    // Draws a mesh (world space, D3DCULL_CCW). Depth-tested and written when `depth` is set: the
    // vertices go through the device's World · View · Projection (perspective-correct). Else
    // simply over what is there (the painter's layers of each scene): the triangles are clipped
    // and projected here and drawn as screen triangles, 16 a draw with affine colours, which the
    // software device draws on its row path (docs/device.md "Aligned passes"), 3–4 times faster
    // than perspective-correct 2×2 quads; the meshes are finely enough divided that affine
    // colours are not told apart.
    bool drawMesh(const Mesh& mesh, bool depth = false) {
        if (mesh.vertices.empty()) return true;
        if (!depth) return drawScreen(toScreen(mesh), D3DCULL_CCW);
        std::vector<Vertex> vertices = mesh.vertices;
        for (Vertex& v : vertices) v.color = fogged(v);
        return check(m_device->SetRenderState(D3DRS_ZENABLE, D3DZB_TRUE), "SetRenderState") &&
               check(m_device->SetFVF(kVertexFvf), "SetFVF") &&
               check(m_device->SetRenderState(D3DRS_CULLMODE, D3DCULL_CCW), "SetRenderState") &&
               check(m_device->DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(vertices.size() / 3), vertices.data(),
                                               sizeof(Vertex)),
                     "DrawPrimitiveUP");
    }

    // The vertex's colour with its glow mask faded by the glow-only fog (Scene::setGlowFog).
    DWORD fogged(const Vertex& v) const {
        if (!(m_glowFogEnd > m_glowFogStart) || (v.color >> 24) == 0) return v.color;
        const glm::vec4 eye = m_view * glm::vec4(v.x, v.y, v.z, 1.0f);
        const float d = glm::length(glm::vec3(eye));
        const float f = std::clamp((m_glowFogEnd - d) / (m_glowFogEnd - m_glowFogStart), 0.0f, 1.0f);
        return DWORD(std::lround(float(v.color >> 24) * f)) << 24 | (v.color & 0xffffffu);
    }

    // Screen-space triangles (XYZRHW, no depth test), at most 16 a draw (the row path's limit).
    bool drawScreen(const std::vector<ScreenVertex>& v, D3DCULL cull = D3DCULL_NONE) {
        if (v.empty()) return true;
        if (!check(m_device->SetRenderState(D3DRS_ZENABLE, D3DZB_FALSE), "SetRenderState") ||
            !check(m_device->SetFVF(kScreenFvf), "SetFVF") ||
            !check(m_device->SetRenderState(D3DRS_CULLMODE, cull), "SetRenderState"))
            return false;
        for (size_t i = 0; i < v.size(); i += 48) {
            const size_t n = std::min<size_t>(48, v.size() - i);
            if (!check(m_device->DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(n / 3), &v[i], sizeof(ScreenVertex)),
                       "DrawPrimitiveUP"))
                return false;
        }
        return true;
    }

    // The mesh's triangles in screen space: through View · Projection in double as the device
    // computes them, clipped (Sutherland–Hodgman, colours interpolated in clip space) against
    // the near plane and a guard band of twice the view, then the viewport; rhw 1 (affine).
    std::vector<ScreenVertex> toScreen(const Mesh& mesh) const {
        struct Clip {
            glm::dvec4 p;
            glm::dvec4 c;  // a r g b, 0…255
        };
        const glm::dmat4 vp = glm::dmat4(m_proj) * glm::dmat4(m_view);
        auto unpack = [](DWORD c) {
            return glm::dvec4(double(c >> 24), double((c >> 16) & 0xFF), double((c >> 8) & 0xFF), double(c & 0xFF));
        };
        auto pack = [](const glm::dvec4& c) {
            auto b = [](double v) { return DWORD(std::clamp(std::lround(v), 0L, 255L)); };
            return b(c[0]) << 24 | b(c[1]) << 16 | b(c[2]) << 8 | b(c[3]);
        };
        // Planes as dot(plane, p) >= 0: z >= 0, 2w ± x >= 0, 2w ± y >= 0.
        const glm::dvec4 planes[5] = {{0, 0, 1, 0}, {1, 0, 0, 2}, {-1, 0, 0, 2}, {0, 1, 0, 2}, {0, -1, 0, 2}};
        std::vector<ScreenVertex> out;
        std::vector<Clip> poly, next;
        for (size_t t = 0; t + 2 < mesh.vertices.size(); t += 3) {
            poly.clear();
            for (size_t k = 0; k < 3; ++k) {
                const Vertex& v = mesh.vertices[t + k];
                poly.push_back({vp * glm::dvec4(v.x, v.y, v.z, 1.0), unpack(fogged(v))});
            }
            for (const glm::dvec4& plane : planes) {
                next.clear();
                for (size_t k = 0; k < poly.size(); ++k) {
                    const Clip& a = poly[k];
                    const Clip& b = poly[(k + 1) % poly.size()];
                    const double da = glm::dot(plane, a.p), db = glm::dot(plane, b.p);
                    if (da >= 0) next.push_back(a);
                    if ((da >= 0) != (db >= 0)) {
                        const double f = da / (da - db);
                        next.push_back({glm::mix(a.p, b.p, f), glm::mix(a.c, b.c, f)});
                    }
                }
                poly.swap(next);
                if (poly.size() < 3) break;
            }
            if (poly.size() < 3) continue;
            std::vector<ScreenVertex> fan;
            bool ok = true;
            for (const Clip& c : poly) {
                if (!(c.p.w > 1e-9)) {
                    ok = false;
                    break;
                }
                fan.push_back({float((1.0 + c.p.x / c.p.w) * double(m_width) / 2.0),
                               float((1.0 - c.p.y / c.p.w) * double(m_height) / 2.0),
                               float(std::clamp(c.p.z / c.p.w, 0.0, 1.0)), 1.0f, pack(c.c)});
            }
            if (!ok) continue;
            for (size_t k = 1; k + 1 < fan.size(); ++k) out.insert(out.end(), {fan[0], fan[k], fan[k + 1]});
        }
        return out;
    }

    // Objects that may hide each other: the depth buffer is cleared over each one's screen
    // rectangle, then they are drawn depth-tested (over the layers drawn before them).
    template <size_t N>
    bool drawObjects(const std::array<Mesh, N>& objects) {
        for (const Mesh& m : objects)
            if (!clearDepthFor(m)) return false;
        for (const Mesh& m : objects)
            if (!drawMesh(m, true)) return false;
        return true;
    }

    // Clears the depth buffer (to 1) over the screen rectangle `mesh` can cover: its projected
    // bounding box plus a pixel, or the whole target when a vertex lies behind the near plane.
    // Depth-tested draws stay inside that rectangle, so the rest of the buffer is never read
    // (clearing 1080p depth costs about 30 ms on the software device; most draws need none).
    bool clearDepthFor(const Mesh& mesh) {
        double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
        bool whole = false;
        for (const Vertex& v : mesh.vertices) {
            glm::dvec4 s;
            if (!project({v.x, v.y, v.z}, s, true)) {
                whole = true;
                break;
            }
            x0 = std::min(x0, s.x);
            y0 = std::min(y0, s.y);
            x1 = std::max(x1, s.x);
            y1 = std::max(y1, s.y);
        }
        D3DRECT r{0, 0, LONG(m_width), LONG(m_height)};
        if (!whole) {
            if (mesh.vertices.empty() || x1 < -1.0 || y1 < -1.0 || x0 > m_width + 1.0 || y0 > m_height + 1.0)
                return true;
            r.x1 = LONG(std::max(0.0, std::floor(x0) - 1.0));
            r.y1 = LONG(std::max(0.0, std::floor(y0) - 1.0));
            r.x2 = LONG(std::min(double(m_width), std::ceil(x1) + 2.0));
            r.y2 = LONG(std::min(double(m_height), std::ceil(y1) + 2.0));
        }
        return check(m_device->Clear(1, &r, D3DCLEAR_ZBUFFER, 0, 1.0f, 0), "Clear");
    }

    // The screen row of the horizon (the camera has no roll, so it is a row): pixel rows above it
    // look up. Clamped to [0, height]; 0 when looking straight down, height when straight up.
    double horizon() const {
        glm::vec3 f = m_at - m_eye;
        f.y = 0.0f;
        if (glm::length(f) < 1e-6f) return m_at.y < m_eye.y ? 0.0 : double(m_height);
        const glm::dvec4 c = glm::dmat4(m_proj) * (glm::dmat4(m_view) * glm::dvec4(glm::dvec3(glm::normalize(f)), 0.0));
        if (!(c.w > 0.0)) return 0.0;
        return std::clamp((1.0 - c.y / c.w) * double(m_height) / 2.0, 0.0, double(m_height));
    }

    // Clears the rows above the horizon to `sky` and the rows below to `ground` (flat colours
    // for free: Clear costs about a millisecond at 1080p).
    bool clearSkyAndGround(D3DCOLOR sky, D3DCOLOR ground) {
        const LONG split = LONG(std::ceil(horizon()));  // rows y < horizon look up
        const D3DRECT up{0, 0, LONG(m_width), split}, down{0, split, LONG(m_width), LONG(m_height)};
        return (split <= 0 || check(m_device->Clear(1, &up, D3DCLEAR_TARGET, sky, 1.0f, 0), "Clear")) &&
               (split >= LONG(m_height) || check(m_device->Clear(1, &down, D3DCLEAR_TARGET, ground, 1.0f, 0), "Clear"));
    }

    // A sky from the top of the target to just below the horizon in screen space (so it costs no
    // perspective division and no depth): a grid whose vertex colours are `palette` (elevation in degrees → colour, ascending)
    // at the elevation of the view ray through the vertex; alpha 0.
    bool drawSky(glm::vec3 eye, const std::vector<std::pair<float, glm::vec3>>& palette, double below = 0.0) {
        const glm::dmat4 inv = glm::inverse(glm::dmat4(m_proj) * glm::dmat4(m_view));
        auto colorAt = [&](float sx, float sy) {
            const double ndcX = 2.0 * double(sx) / double(m_width) - 1.0;  // the inverse of the viewport
            const double ndcY = 1.0 - 2.0 * double(sy) / double(m_height);
            const glm::dvec4 p = inv * glm::dvec4(ndcX, ndcY, 1.0, 1.0);
            const glm::dvec3 dir = glm::normalize(glm::dvec3(p) / p.w - glm::dvec3(eye));
            const float e = float(std::asin(std::clamp(dir.y, -1.0, 1.0)) * 180.0 / 3.14159265358979);
            if (e <= palette.front().first) return palette.front().second;
            for (size_t i = 1; i < palette.size(); ++i)
                if (e <= palette[i].first)
                    return glm::mix(palette[i - 1].second, palette[i].second,
                                    (e - palette[i - 1].first) / (palette[i].first - palette[i - 1].first));
            return palette.back().second;
        };
        // Down to the horizon's row and `below` (a fraction of the height) further, in 24 bands.
        const double bottom = std::min(double(m_height), std::ceil(horizon()) + below * double(m_height)) - 0.5;
        if (bottom <= -0.5) return true;
        const int nx = 8, ny = 24;
        std::vector<ScreenVertex> v;
        auto vertex = [&](int i, int j) {
            const float x = -0.5f + float(m_width) * float(i) / float(nx), y = float(-0.5 + (bottom + 0.5) * double(j) / double(ny));
            return ScreenVertex{x, y, 1.0f, 1.0f, packColor(colorAt(x, y), false)};
        };
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const ScreenVertex a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
                v.insert(v.end(), {a, b, c, a, c, d});
            }
        return drawScreen(v);
    }

private:
    // The depth surface for a target of w × h, made on first use, remade for another size.
    bool depthSurface(Device& device, UINT w, UINT h) {
        if (m_depthDevice != &device) {
            m_depth = Handle::Null;  // a handle of another device means nothing here
            m_depthDevice = &device;
        }
        if (m_depth != Handle::Null) {
            D3DSURFACE_DESC d;
            const bool alive = device.GetDesc(m_depth, &d) == D3D_OK && (d.Usage & D3DUSAGE_DEPTHSTENCIL);
            if (alive && d.Width == w && d.Height == h) return true;
            if (alive) device.Release(m_depth);
            m_depth = Handle::Null;
        }
        return check(device.CreateDepthStencilSurface(w, h, D3DFMT_D24S8, &m_depth), "CreateDepthStencilSurface");
    }

    bool setUp(Handle target) {
        Device& d = *m_device;
        if (!check(d.SetRenderTarget(0, target), "SetRenderTarget") ||
            !check(d.SetDepthStencilSurface(m_depth), "SetDepthStencilSurface") ||
            !check(d.SetPixelShader(Handle::Null), "SetPixelShader"))
            return false;
        const std::pair<D3DRENDERSTATETYPE, DWORD> states[] = {
            {D3DRS_ZENABLE, D3DZB_FALSE},
            {D3DRS_ZWRITEENABLE, 1},
            {D3DRS_ZFUNC, D3DCMP_LESSEQUAL},
            {D3DRS_CULLMODE, D3DCULL_CCW},
            {D3DRS_FILLMODE, D3DFILL_SOLID},
            {D3DRS_SHADEMODE, D3DSHADE_GOURAUD},
            {D3DRS_ALPHABLENDENABLE, 0},
            {D3DRS_ALPHATESTENABLE, 0},
            {D3DRS_FOGENABLE, 0},
            {D3DRS_SCISSORTESTENABLE, 0},
            {D3DRS_COLORWRITEENABLE, 0xF},
            {D3DRS_SPECULARENABLE, 0},
        };
        for (const auto& [s, v] : states)
            if (!check(d.SetRenderState(s, v), "SetRenderState")) return false;
        const std::tuple<DWORD, D3DTEXTURESTAGESTATETYPE, DWORD> stages[] = {
            {0, D3DTSS_COLOROP, D3DTOP_SELECTARG1}, {0, D3DTSS_COLORARG1, D3DTA_DIFFUSE},
            {0, D3DTSS_ALPHAOP, D3DTOP_SELECTARG1}, {0, D3DTSS_ALPHAARG1, D3DTA_DIFFUSE},
            {0, D3DTSS_RESULTARG, D3DTA_CURRENT},   {1, D3DTSS_COLOROP, D3DTOP_DISABLE},
            {1, D3DTSS_ALPHAOP, D3DTOP_DISABLE},
        };
        for (const auto& [stage, type, v] : stages)
            if (!check(d.SetTextureStageState(stage, type, v), "SetTextureStageState")) return false;
        return check(d.Clear(0, nullptr, D3DCLEAR_TARGET, clearColor(), 1.0f, 0), "Clear");
    }

    std::string_view m_name;
    Device* m_device = nullptr;
    std::string* m_error = nullptr;
    const Device* m_depthDevice = nullptr;
    Handle m_depth = Handle::Null;
    UINT m_width = 1, m_height = 1;
    glm::mat4 m_view{1.0f}, m_proj{1.0f};
    glm::vec3 m_eye{0.0f}, m_at{0.0f, 0.0f, 1.0f};
};


}  // namespace glare::scene_kit
