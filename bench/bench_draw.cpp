// Benchmarks of whole draws through emu::Device::DrawPrimitiveUP (Google Benchmark; never run by
// ctest): the 1080p passes of PERF.md — the 4-tap bilinear blur (ps_1_1 tex t0..t3 + mul/mad
// with c0 weights) and 1:1 copies — on 1 and 2 worker threads, fx8. Each iteration is one draw of
// the half-pixel 1:1 quad over a 1920×1080 A8R8G8B8 target from a 1920×1080 A8R8G8B8 texture.
// How to run and what the numbers mean: bench/README.md "bench_draw".
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <chrono>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bench/bench_shaders.h"
#include "emu/device.h"
#include "emu/fullscreen.h"
#include "emu/raster.h"
#include "ps11/hardware.h"

namespace {

using bench::kBlur4;
using bench::kCopy;

using namespace emu;

constexpr UINT kW = 1920, kH = 1080;

struct QuadVertex {
    float x, y, z, rhw;
    float uv[4][2];
};

// Down2: 1080p texture to a 960×540 target, one bilinear tap on the corner of each 2×2 block.
// Down2Mip: the same from a mip-mapped 1080p texture, MIP filter POINT: every quad picks level 1
// (960×540), read 1:1 — the row path over that level.
// Down8Point: 1080p texture to 240×135, one point tap per 8×8 block (the adaptive glare's bright
// pass reads the scene so): each pixel row reads a texel row eight below the last one's.
// Down4: 1080p texture to 480×270, the blur program's four bilinear taps at ±1 texel around the
// centre of each 4×4 block (the 16-texel box of a bloom chain's first reduction).
// Sprites: 400 quads of 64x64 pixels at sub-pixel positions over a 1080p target, each a 32x32
// texture magnified 2x and scaled by c0, added ONE/ONE (the sprites technique's draw).
// SpritesFfp: the sprites technique's draw as glare/sprites.cpp makes it on its `lights` scene at
// 1080p: 20 quads of 113.4×113.4 pixels at sub-pixel positions, fixed function (texture ×
// diffuse, a colour per quad), the 128×128 glare image read from 0.06 to 0.94 bilinear (magnified
// about 1.05×, the shrunk sprites), added ONE/ONE; the texture a bright centre falling off.
// SpritesSmall: the same draw as on the `sparse` scene's 480×270 panel (bench_glare): 1 296 quads
// of 28.4×28.4 pixels, overlapping about eight deep, the image minified about 4:1 (each pixel row
// reads texel rows no other pixel row reads).
// Tiny: the blur on a 1×1 target from a 1×1 texture (a glare technique's adaptation step): what a
// draw costs besides its pixels.
// Weighted4: the glow's blur passes (glare/shaders/weighted4.psh) at 480×270 — four POINT taps at
// whole-texel horizontal offsets −2…+1 with weights c0..c3, added ONE/ONE onto the target.
// CompositeAdd: the last pass of glow, quarter, pyramid and sprites (glare/shaders/scale.psh) —
// a 480×270 glare magnified 4× (bilinear) × c0, added ONE/ONE onto the 1080p target.
// CompositeCopy: the same with c0 = (1, 1, 1, 0), as glow, quarter and sprites set it: the program
// copies its tap (r, g, b; alpha 0) whatever it reads, so every window is a copy.
// CompositePutOff: CompositeCopy onto a StretchRect of a 1080p scene made just before it, as the
// glare techniques' copy_scene and composite do: the renderer puts the copy off and the draw
// makes it as it stores (docs/device.md "StretchRect"); the time is the copy's and the draw's.
// Composite: a glare technique's last pass — the 1080p scene 1:1 (t0, point) and a 240×135 glare
// texture magnified 8× (t1, bilinear), screen blend `mad r0, t1, 1-t0, t0`.
// Rotated: the 1080p blur with its texture coordinates turned by 10 degrees about the centre (u
// and v each follow both x and y: the fx8 row path samples such taps per pixel).
// PerspectiveMip: the same from a texture with its whole mip chain, MIP filter POINT: each pixel
// at the level its 2×2 quad picks (levels 0 and 1 across the screen). PerspectiveTrilinear: MIP
// filter LINEAR, each pixel a blend of two levels where its quad's level of detail is above 0.
// Perspective: the 1080p linear copy through a quad whose right edge has rhw ½ (perspective-
// correct coordinates, divided per pixel).
// Projected: the 1080p linear copy read through D3DTTFF_PROJECTED (COUNT4): each vertex's
// coordinates (u·q, v·q, 0, q), q 1 on the left edge and 2 on the right, divided per pixel.
// Kill: the 1080p linear copy with `texkill t1`, set 1's u running from −0.5 to 0.5 across the
// screen: the left half of every row killed.
// Dependent: a ps_1_4 dependent read at 1080p on the 1.4 class (fx12) — `texld r0, t0`, then
// `texld r1, r0` (the first lookup's colour as the coordinates of the second, bilinear, same
// texture): the row path, whose pre-sampled runs execute the dependent read itself.
enum class Pass {
    Blur4,
    CopyPoint,
    CopyLinear,
    CopySmall,
    Down2,
    Down4,
    Blur4Small,
    Sprites,
    SpritesFfp,
    SpritesSmall,
    Tiny,
    Composite,
    Weighted4,
    CompositeAdd,
    CompositeCopy,
    CompositePutOff,
    Rotated,
    Perspective,
    Projected,
    Kill,
    Dependent,
    Down2Mip,
    PerspectiveMip,
    PerspectiveTrilinear,
    Down8Point,
    Count  // (not a pass: how many there are)
};
constexpr int kPasses = int(Pass::Count);

// One device per (pass, threads), built once: the texture's sampler copy is made by a warm-up
// draw, so iterations time the draw alone.
struct Scene {
    std::unique_ptr<Device> dev;
    std::vector<QuadVertex> quad;
    std::vector<emu::QuadVertex> ffpQuad;  // SpritesFfp (diffuse per vertex)
    Handle target{}, putOffFrom{};         // CompositePutOff: the scene copied onto the target first
    bool ok = false;

    UINT w = kW, h = kH;

    Scene(Pass pass, int threads, bool aligned = true) {
        if (pass == Pass::CopySmall || pass == Pass::Blur4Small || pass == Pass::Down8Point) w = kW / 8, h = kH / 8;  // 240×135, the small passes of PERF.md
        const bool trilinear = pass == Pass::PerspectiveTrilinear;
        const bool mip = pass == Pass::Down2Mip || pass == Pass::PerspectiveMip || trilinear;
        if (pass == Pass::Down2 || pass == Pass::Down2Mip) w = kW / 2, h = kH / 2;
        if (pass == Pass::Down4 || pass == Pass::Weighted4 || pass == Pass::SpritesSmall) w = kW / 4, h = kH / 4;
        if (pass == Pass::Tiny) w = h = 1;
        // The texture: the target's size, or 1080p for the reductions.
        const bool down = pass == Pass::Down2 || pass == Pass::Down2Mip || pass == Pass::Down4 || pass == Pass::Down8Point;
        const bool putOff = pass == Pass::CompositePutOff;
        const bool addGlare = pass == Pass::CompositeAdd || pass == Pass::CompositeCopy || putOff;
        const bool ffp = pass == Pass::SpritesFfp || pass == Pass::SpritesSmall;
        const UINT tw = down ? kW : pass == Pass::Sprites ? 32 : ffp ? 128 : addGlare ? w / 4 : w;
        const UINT th = down ? kH : pass == Pass::Sprites ? 32 : ffp ? 128 : addGlare ? h / 4 : h;
        DeviceOptions o;
        o.software.threads = threads;
        o.software.alignedPasses = aligned;
        if (pass == Pass::Dependent) o.hardware = &ps11::defaultHardware(4);  // the ps_1_4 class: radeon8500, fx12
        dev = std::make_unique<Device>(o);
        Handle rt{}, tex{}, ps{};
        if (dev->CreateRenderTarget(w, h, D3DFMT_A8R8G8B8, 0, &rt) != D3D_OK) return;
        if (dev->SetRenderTarget(0, rt) != D3D_OK) return;
        target = rt;
        if (putOff) {  // the scene: random bytes, lockable
            if (dev->CreateRenderTarget(w, h, D3DFMT_A8R8G8B8, 1, &putOffFrom) != D3D_OK) return;
            D3DLOCKED_RECT sl;
            if (dev->LockRect(putOffFrom, &sl, nullptr, 0) != D3D_OK) return;
            std::mt19937 srng(7);
            for (UINT y = 0; y < h; ++y)
                for (UINT i = 0; i < w * 4; ++i) static_cast<uint8_t*>(sl.pBits)[size_t(y) * size_t(sl.Pitch) + i] = uint8_t(srng());
            if (dev->UnlockRect(putOffFrom) != D3D_OK) return;
        }
        if (dev->CreateTexture(tw, th, mip ? 0 : 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) != D3D_OK) return;
        D3DLOCKED_RECT lr;
        std::mt19937 rng(42);
        for (UINT level = 0; level < dev->GetLevelCount(tex); ++level) {
            const UINT lw = std::max(1u, tw >> level), lh = std::max(1u, th >> level);
            if (dev->LockRect(tex, level, &lr, nullptr, 0) != D3D_OK) return;
            for (UINT y = 0; y < lh; ++y) {
                auto* row = reinterpret_cast<uint32_t*>(static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch));
                for (UINT x = 0; x < lw; ++x) {
                    row[x] = rng();
                    if (ffp) {  // grey, alpha 255, falling off from the centre
                        const double d = std::hypot(double(x) - 63.5, double(y) - 63.5) / 64.0;
                        const uint32_t g = uint32_t(std::lround(255.0 * std::exp(-6.0 * d)));
                        row[x] = 0xff000000u | g << 16 | g << 8 | g;
                    }
                }
            }
            dev->UnlockRect(tex, level);
        }
        Handle glare{};
        if (pass == Pass::Composite) {
            if (dev->CreateTexture(w / 8, h / 8, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &glare) != D3D_OK) return;
            if (dev->LockRect(glare, 0, &lr, nullptr, 0) != D3D_OK) return;
            for (UINT y = 0; y < h / 8; ++y) {
                auto* row = reinterpret_cast<uint32_t*>(static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch));
                for (UINT x = 0; x < w / 8; ++x) row[x] = rng();
            }
            dev->UnlockRect(glare, 0);
        }
        const bool weighted = pass == Pass::Weighted4;
        const bool fourTaps = pass == Pass::Blur4 || pass == Pass::Down4 || pass == Pass::Blur4Small ||
                              pass == Pass::Tiny || weighted || pass == Pass::Rotated;
        const int stages = fourTaps ? 4 : pass == Pass::Composite ? 2 : 1;
        for (int s = 0; s < stages; ++s) {
            const DWORD filter =
                pass == Pass::CopyPoint || pass == Pass::Down8Point || weighted || (pass == Pass::Composite && s == 0)
                    ? D3DTEXF_POINT
                    : D3DTEXF_LINEAR;
            dev->SetTexture(DWORD(s), pass == Pass::Composite && s == 1 ? glare : tex);
            dev->SetSamplerState(DWORD(s), D3DSAMP_MINFILTER, filter);
            dev->SetSamplerState(DWORD(s), D3DSAMP_MAGFILTER, filter);
            dev->SetSamplerState(DWORD(s), D3DSAMP_ADDRESSU, D3DTADDRESS_CLAMP);
            dev->SetSamplerState(DWORD(s), D3DSAMP_ADDRESSV, D3DTADDRESS_CLAMP);
            dev->SetSamplerState(DWORD(s), D3DSAMP_MIPFILTER,
                                 trilinear ? D3DTEXF_LINEAR : mip ? D3DTEXF_POINT : D3DTEXF_NONE);
        }
        const char* const kSprite = "ps_1_1\ntex t0\nmul r0, t0, c0\n";
        const char* const kScreen = "ps_1_1\ntex t0\ntex t1\nmad r0, t1, 1-t0, t0\n";
        const char* const kWeighted4 =
            "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c1, r0\nmad r0, t2, c2, r0\n"
            "mad r0, t3, c3, r0\n";
        const char* const kScale = "ps_1_1\ntex t0\nmul r0, t0, c0\n";
        const char* const kDependent = "ps_1_4\ntexld r0, t0\nphase\ntexld r1, r0\nmov r0, r1\n";
        const char* const kKill = "ps_1_1\ntex t0\ntexkill t1\nmov r0, t0\n";
        if (dev->CreatePixelShaderFromText(pass == Pass::Dependent   ? kDependent
                                           : pass == Pass::Kill      ? kKill
                                           : weighted                ? kWeighted4
                                           : addGlare                ? kScale
                                           : fourTaps                ? kBlur4
                                           : pass == Pass::Sprites   ? kSprite
                                           : pass == Pass::Composite ? kScreen
                                                                     : kCopy,
                                           &ps) != D3D_OK)
            return;
        dev->SetPixelShader(ps);
        const float c0[4] = {0.25f, 0.25f, 0.25f, 0.25f};
        dev->SetPixelShaderConstantF(0, c0, 1);
        if (weighted) {
            const float cs[4][4] = {{0.12f, 0.12f, 0.12f, 0.12f},
                                    {0.2f, 0.2f, 0.2f, 0.2f},
                                    {0.2f, 0.2f, 0.2f, 0.2f},
                                    {0.12f, 0.12f, 0.12f, 0.12f}};
            dev->SetPixelShaderConstantF(0, cs[0], 4);
        }
        if (addGlare) {
            const float strength[4] = {0.8f, 0.8f, 0.8f, 0.8f}, copy[4] = {1, 1, 1, 0};
            dev->SetPixelShaderConstantF(0, pass == Pass::CompositeAdd ? strength : copy, 1);
        }
        if (weighted || addGlare) {
            dev->SetRenderState(D3DRS_ALPHABLENDENABLE, 1);
            dev->SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE);
            dev->SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE);
        }
        dev->SetFVF(D3DFVF_XYZRHW | D3DFVF_TEX4);
        if (pass == Pass::Projected) {  // two sets of four components: the same 32 bytes a vertex
            dev->SetFVF(D3DFVF_XYZRHW | D3DFVF_TEX2 | D3DFVF_TEXCOORDSIZE4(0) | D3DFVF_TEXCOORDSIZE4(1));
            dev->SetTextureStageState(0, D3DTSS_TEXTURETRANSFORMFLAGS, D3DTTFF_PROJECTED | D3DTTFF_COUNT4);
        }
        // The half-pixel quad; blur taps at ±0.5 texel diagonally (bilinear weights ½: each tap
        // averages a 2×2 block), the copy at the texel centres; Down4's taps at ±1 texel.
        const float k = pass == Pass::Down4 ? 1.0f : 0.5f;
        const float off[4][2] = {{-k, -k}, {k, -k}, {-k, k}, {k, k}};
        const float wOff[4][2] = {{-2, 0}, {-1, 0}, {0, 0}, {1, 0}};
        const float xs[4] = {-0.5f, w - 0.5f, w - 0.5f, -0.5f}, ys[4] = {-0.5f, -0.5f, h - 0.5f, h - 0.5f};
        const float us[4] = {0, 1, 1, 0}, vs[4] = {0, 0, 1, 1};
        if (ffp) {
            dev->SetPixelShader(Handle::Null);
            dev->SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_MODULATE);
            dev->SetTextureStageState(0, D3DTSS_COLORARG1, D3DTA_TEXTURE);
            dev->SetTextureStageState(0, D3DTSS_COLORARG2, D3DTA_DIFFUSE);
            dev->SetTextureStageState(1, D3DTSS_COLOROP, D3DTOP_DISABLE);
            dev->SetRenderState(D3DRS_ALPHABLENDENABLE, 1);
            dev->SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE);
            dev->SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE);
            dev->SetFVF(kQuadFvf);
            const bool small = pass == Pass::SpritesSmall;
            const float size = small ? 28.4f : 113.4f, t0 = 0.06f, t1 = 0.94f;
            std::uniform_real_distribution<float> px(0.0f, float(w) - size - 1), py(0.0f, float(h) - size - 1);
            const QuadCoords uv{t0, t0, t1, t1};
            for (int k = 0; k < (small ? 1296 : 20); ++k) {
                const float x0 = px(rng), y0 = py(rng);
                const DWORD colour = 0xff000000u | (rng() & 0x7f7f7fu);
                const auto q = halfPixelQuad(x0, y0, x0 + size, y0 + size, {uv, uv, uv, uv}, colour);
                for (int i : {0, 1, 2, 2, 1, 3}) ffpQuad.push_back(q[size_t(i)]);
            }
            ok = draw();
            return;
        }
        if (pass == Pass::Sprites) {
            dev->SetRenderState(D3DRS_ALPHABLENDENABLE, 1);
            dev->SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE);
            dev->SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE);
            std::uniform_real_distribution<float> px(-32.0f, float(w) - 32.0f), py(-32.0f, float(h) - 32.0f);
            for (int k = 0; k < 400; ++k) {
                const float x0 = px(rng), y0 = py(rng);
                const float sx[4] = {x0, x0 + 64, x0 + 64, x0}, sy[4] = {y0, y0, y0 + 64, y0 + 64};
                for (int c : {0, 1, 2, 0, 2, 3}) {
                    QuadVertex q{sx[c], sy[c], 0.0f, 1.0f, {}};
                    q.uv[0][0] = us[c], q.uv[0][1] = vs[c];
                    quad.push_back(q);
                }
            }
            ok = draw();
            return;
        }
        const float turn = pass == Pass::Rotated ? 10.0f * 3.14159265f / 180.0f : 0.0f;
        for (int c : {0, 1, 2, 0, 2, 3}) {
            const bool perspective = pass == Pass::Perspective || pass == Pass::PerspectiveMip || trilinear;
            const float rhw = perspective && (c == 1 || c == 2) ? 0.5f : 1.0f;
            QuadVertex q{xs[c], ys[c], 0.0f, rhw, {}};
            const float ru = 0.5f + std::cos(turn) * (us[c] - 0.5f) - std::sin(turn) * (vs[c] - 0.5f);
            const float rv = 0.5f + std::sin(turn) * (us[c] - 0.5f) + std::cos(turn) * (vs[c] - 0.5f);
            for (int s = 0; s < 4; ++s) {
                const float(*o)[2] = weighted ? wOff : off;
                q.uv[s][0] = ru + (fourTaps ? o[s][0] / float(tw) : 0.0f);
                q.uv[s][1] = rv + (fourTaps ? o[s][1] / float(th) : 0.0f);
            }
            if (pass == Pass::Kill) q.uv[1][0] = us[c] - 0.5f;  // set 1's u: killed where below 0
            if (pass == Pass::Projected) {  // set 0: (u·q, v·q, 0, q)
                const float qv = c == 1 || c == 2 ? 2.0f : 1.0f;
                q.uv[0][0] *= qv, q.uv[0][1] *= qv;
                q.uv[1][0] = 0.0f, q.uv[1][1] = qv;
            }
            quad.push_back(q);
        }
        ok = draw();  // warm-up: builds the sampler's copy of the texture and the executor
    }

    bool draw() {
        if (putOffFrom != Handle{} && dev->StretchRect(putOffFrom, nullptr, target, nullptr, D3DTEXF_POINT) != D3D_OK)
            return false;
        if (!ffpQuad.empty())
            return dev->DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(ffpQuad.size() / 3), ffpQuad.data(),
                                        sizeof(emu::QuadVertex)) == D3D_OK;
        return dev->DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(quad.size() / 3), quad.data(), sizeof(QuadVertex)) == D3D_OK;
    }
};

Scene& scene(Pass pass, int threads, bool aligned = true) {
    static std::unique_ptr<Scene> scenes[kPasses][3][2];
    auto& s = scenes[int(pass)][threads][aligned];
    if (!s) s = std::make_unique<Scene>(pass, threads, aligned);
    return *s;
}

// The aligned-pass path against the quad path (DeviceOptions::alignedPasses off) on the same
// pass: each iteration draws once with each, alternating which goes first, each timed on its own
// (wall time); the reported time is the aligned draw's, `quad_ms` and `speedup` (quad / aligned,
// ratio of the sums over the same iterations) compare them.
void BM_AlignedVsQuads(benchmark::State& state, Pass pass) {
    const int threads = int(state.range(0));
    Scene& a = scene(pass, threads, true);
    Scene& q = scene(pass, threads, false);
    if (!a.ok || !q.ok) {
        state.SkipWithError("device refused the setup");
        return;
    }
    double aSum = 0, qSum = 0;
    bool flip = false;
    for (auto _ : state) {
        auto time = [](Scene& sc) {
            const auto t0 = std::chrono::steady_clock::now();
            sc.draw();
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        };
        double ta, tq;
        if (flip) {
            tq = time(q);
            ta = time(a);
        } else {
            ta = time(a);
            tq = time(q);
        }
        flip = !flip;
        aSum += ta;
        qSum += tq;
        state.SetIterationTime(ta);
    }
    const double n = double(std::max<int64_t>(state.iterations(), 1));
    state.counters["quad_ms"] = qSum / n * 1e3;
    state.counters["aligned_ms"] = aSum / n * 1e3;
    state.counters["speedup"] = aSum > 0 ? qSum / aSum : 0;
    state.counters["aligned_shaded/px"] = double(a.dev->lastDrawStats().pixelsShaded) / (double(a.w) * a.h);
}

void BM_Draw(benchmark::State& state, Pass pass) {
    const int threads = int(state.range(0));
    Scene& sc = scene(pass, threads);
    if (!sc.ok) {
        state.SkipWithError(("device refused the setup: " + sc.dev->lastError().message).c_str());
        return;
    }
    for (auto _ : state) {
        if (!sc.draw()) {
            state.SkipWithError(sc.dev->lastError().message.c_str());
            return;
        }
    }
    const DrawStats& st = sc.dev->lastDrawStats();
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(sc.w) * sc.h);
    state.counters["shaded/px"] = double(st.pixelsShaded) / (double(sc.w) * sc.h);
    state.counters["instr/px"] = double(st.instructions) / double(st.pixelsShaded ? st.pixelsShaded : 1);
    state.counters["texels/px"] = double(st.texelsFetched) / (double(sc.w) * sc.h);
}

// The rasteriser alone over the 1080p half-pixel quad: spans with the blur's inputs (4 slots:
// u, v as planes, w = 0 and q = 1 constant), no shading — the draw's own cost per pixel.
void BM_Raster(benchmark::State& state) {
    const int slots = int(state.range(0));
    auto V = [&](double x, double y, float u, float v) {
        ScreenVertex s;
        s.x = x;
        s.y = y;
        for (int t = 0; t < slots; ++t) {
            s.attr[size_t(attrTex(t, 0))] = u + 0.5f * float(t) / kW;
            s.attr[size_t(attrTex(t, 1))] = v;
            s.attr[size_t(attrTex(t, 3))] = 1.0f;
        }
        return s;
    };
    const ScreenVertex a = V(-0.5, -0.5, 0, 0), b = V(kW - 0.5, -0.5, 1, 0), c = V(kW - 0.5, kH - 0.5, 1, 1),
                       d = V(-0.5, kH - 0.5, 0, 1);
    const ScreenTriangle tris[2] = {ScreenTriangle{{a, b, c}}, ScreenTriangle{{a, c, d}}};
    uint64_t used = 0;
    for (int t = 0; t < slots; ++t) used |= uint64_t(0xF) << attrTex(t, 0);
    auto span = std::make_unique<QuadSpan>();
    uint64_t lanes = 0;
    const std::function<void(QuadSpan&)> emit = [&](QuadSpan& sp) { lanes += uint64_t(sp.count); };
    for (auto _ : state) {
        for (const ScreenTriangle& t : tris) {
            TriangleSetup s;
            if (setupTriangle(t, used, ClipRect{0, 0, int(kW), int(kH)}, s))
                rasterizeRows(s, 0, kH, used, false, *span, emit);
        }
        benchmark::DoNotOptimize(span->attr[0][0]);
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(kW) * kH);
    state.counters["ns/px"] = benchmark::Counter(
        double(kW) * kH * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// A freshly drawn 1080p render-target texture read by a small pass: each iteration clears the
// target (`whole`: all of it; else all but its last column, a clear that leaves the X8R8G8B8 X
// bytes of that column unknown) and then draws the 240×135 point reduction from it (one texel in
// 64; the adaptive glare's bright pass). What the first read of a freshly written target costs:
// A8R8G8B8, an X8R8G8B8 cleared whole and the float targets are sampled where they lie
// (docs/device.md "Textures"); the partly cleared X8R8G8B8 is copied whole with alpha forced first.
void BM_FreshTargetRead(benchmark::State& state, D3DFORMAT format, bool whole) {
    DeviceOptions o;
    o.software.threads = int(state.range(0));
    Device dev(o);
    Handle tex{}, level{}, small{}, ps{};
    bool ok = dev.CreateTexture(kW, kH, 1, D3DUSAGE_RENDERTARGET, format, D3DPOOL_DEFAULT, &tex) == D3D_OK &&
              dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK &&
              dev.CreateRenderTarget(kW / 8, kH / 8, D3DFMT_A8R8G8B8, 0, &small) == D3D_OK &&
              dev.CreatePixelShaderFromText(bench::kCopy, &ps) == D3D_OK && dev.SetPixelShader(ps) == D3D_OK &&
              dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_TEX4) == D3D_OK;
    for (D3DSAMPLERSTATETYPE f : {D3DSAMP_MINFILTER, D3DSAMP_MAGFILTER})
        ok = ok && dev.SetSamplerState(0, f, D3DTEXF_POINT) == D3D_OK;
    if (!ok) {
        state.SkipWithError(("device refused the setup: " + dev.lastError().message).c_str());
        return;
    }
    const float w = kW / 8, h = kH / 8;
    std::vector<QuadVertex> quad;
    const float xs[4] = {-0.5f, w - 0.5f, w - 0.5f, -0.5f}, ys[4] = {-0.5f, -0.5f, h - 0.5f, h - 0.5f};
    const float us[4] = {0, 1, 1, 0}, vs[4] = {0, 0, 1, 1};
    for (int c : {0, 1, 2, 0, 2, 3}) {
        QuadVertex q{xs[c], ys[c], 0.0f, 1.0f, {}};
        q.uv[0][0] = us[c], q.uv[0][1] = vs[c];
        quad.push_back(q);
    }
    const D3DRECT most{0, 0, LONG(kW - 1), LONG(kH)};
    DWORD colour = 0;
    for (auto _ : state) {
        colour = (colour + 0x010203u) & 0xffffffu;  // a new value each time: every clear writes
        ok = dev.SetRenderTarget(0, level) == D3D_OK &&
             dev.Clear(whole ? 0 : 1, whole ? nullptr : &most, D3DCLEAR_TARGET, colour, 1.0f, 0) == D3D_OK &&
             dev.SetRenderTarget(0, small) == D3D_OK && dev.SetTexture(0, tex) == D3D_OK &&
             dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, quad.data(), sizeof(QuadVertex)) == D3D_OK &&
             dev.SetTexture(0, Handle::Null) == D3D_OK;
        if (!ok) {
            state.SkipWithError(dev.lastError().message.c_str());
            return;
        }
    }
}

// What deciding tiles costs against shading them (docs/device.md "Tile skipping"), on a 1080p
// texture like the `sparse` scene's passes read: 36 bright 24×24 squares (1 % of the pixels) over
// dark noise (8–40 a channel, never black) for the bright pass (argument 0: `sub_sat r0, t0, c0`,
// c0 = 0.6, point), over black for the blur (1: the 4-tap blur, c0 = 0.25, bilinear taps at ±½
// texel diagonally, as a glare's blur of its bright pass reads). Drawn 1:1 on a device that decides
// every tile (skipping on, deciding by the share of tiles saved: not timed) and on one that shades
// every tile (skipping off), alternated, each timed on its own. The texture is uploaded once, so
// its tile facts are scanned once (before timing): the decided draw's time is its decisions and
// the tiles they leave to shade. Reported: the decided draw's time; `plain_ms`, `decided_ms`, the
// tiles shaded and filled by the decided draw, `shade_ns` (the plain draw per tile) and
// `decide_ns`: (decided − plain × shaded / all tiles) over the tiles saved — what each tile saved
// cost to decide and fill, counting the shaded tiles at the plain draw's cost per tile.
void BM_TileDecisions(benchmark::State& state) {
    const int threads = int(state.range(0));
    const bool blur = state.range(1) == 1;
    struct Side {
        std::unique_ptr<Device> dev;
        bool ok = false;
    } side[2];
    std::vector<uint32_t> texels(size_t(kW) * kH);
    std::mt19937 rng(7);
    for (uint32_t& t : texels) {
        uint32_t v = 0xff000000u;
        for (int c = 0; c < 3; ++c) v |= (blur ? 0u : 8u + rng() % 33u) << (8 * c);
        t = v;
    }
    for (int k = 0; k < 36; ++k) {
        const UINT x0 = rng() % (kW - 24), y0 = rng() % (kH - 24);
        for (UINT y = y0; y < y0 + 24; ++y)
            for (UINT x = x0; x < x0 + 24; ++x) texels[size_t(y) * kW + x] = 0xffe0f0ffu;
    }
    std::vector<QuadVertex> quad;
    const float xs[4] = {-0.5f, kW - 0.5f, kW - 0.5f, -0.5f}, ys[4] = {-0.5f, -0.5f, kH - 0.5f, kH - 0.5f};
    const float us[4] = {0, 1, 1, 0}, vs[4] = {0, 0, 1, 1};
    const float off[4][2] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {-0.5f, 0.5f}, {0.5f, 0.5f}};
    for (int c : {0, 1, 2, 0, 2, 3}) {
        QuadVertex q{xs[c], ys[c], 0.0f, 1.0f, {}};
        for (int t = 0; t < 4; ++t) {
            q.uv[t][0] = us[c] + (blur ? off[t][0] / float(kW) : 0.0f);
            q.uv[t][1] = vs[c] + (blur ? off[t][1] / float(kH) : 0.0f);
        }
        quad.push_back(q);
    }
    auto draw = [&](Device& dev) {
        return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, quad.data(), sizeof(QuadVertex)) == D3D_OK;
    };
    for (int k = 0; k < 2; ++k) {
        DeviceOptions o;
        o.software.threads = threads;
        o.software.skipTiles = k == 0;
        o.software.timeTiles = false;
        side[k].dev = std::make_unique<Device>(o);
        Device& dev = *side[k].dev;
        Handle rt{}, tex{}, ps{};
        D3DLOCKED_RECT lr{};
        bool ok = dev.CreateRenderTarget(kW, kH, D3DFMT_A8R8G8B8, 0, &rt) == D3D_OK &&
                  dev.SetRenderTarget(0, rt) == D3D_OK &&
                  dev.CreateTexture(kW, kH, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK &&
                  dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK;
        if (ok) {
            for (UINT y = 0; y < kH; ++y)
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch), &texels[size_t(y) * kW],
                            kW * 4);
            ok = dev.UnlockRect(tex, 0) == D3D_OK;
        }
        const float w = blur ? 0.25f : 0.6f, c0[4] = {w, w, w, w};
        ok = ok &&
             dev.CreatePixelShaderFromText(blur ? bench::kBlur4 : "ps_1_1\ntex t0\nsub_sat r0, t0, c0\n", &ps) ==
                 D3D_OK &&
             dev.SetPixelShader(ps) == D3D_OK && dev.SetPixelShaderConstantF(0, c0, 1) == D3D_OK &&
             dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_TEX4) == D3D_OK;
        for (DWORD t = 0; t < (blur ? 4u : 1u); ++t) {
            ok = ok && dev.SetTexture(t, tex) == D3D_OK;
            for (D3DSAMPLERSTATETYPE f : {D3DSAMP_MINFILTER, D3DSAMP_MAGFILTER})
                ok = ok && dev.SetSamplerState(t, f, blur ? D3DTEXF_LINEAR : D3DTEXF_POINT) == D3D_OK;
        }
        side[k].ok = ok && draw(dev) && draw(dev);  // the facts scanned, the executor made
        if (!side[k].ok) {
            state.SkipWithError(("device refused the setup: " + dev.lastError().message).c_str());
            return;
        }
    }
    double sum[2] = {0, 0};
    bool flip = false;
    for (auto _ : state) {
        double t[2];
        for (int i = 0; i < 2; ++i) {
            const int k = flip ? 1 - i : i;
            const auto t0 = std::chrono::steady_clock::now();
            if (!draw(*side[k].dev)) {
                state.SkipWithError(side[k].dev->lastError().message.c_str());
                return;
            }
            t[k] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        flip = !flip;
        sum[0] += t[0], sum[1] += t[1];
        state.SetIterationTime(t[0]);
    }
    const double n = double(std::max<int64_t>(state.iterations(), 1));
    const DrawStats& st = side[0].dev->lastDrawStats();
    const double all = double(st.tilesShaded + st.tilesFilled + st.tilesCopied + st.tilesSkipped);
    const double decided = sum[0] / n, plain = sum[1] / n;
    state.counters["decided_ms"] = decided * 1e3;
    state.counters["plain_ms"] = plain * 1e3;
    state.counters["tiles_shaded"] = double(st.tilesShaded);
    state.counters["tiles_filled"] = double(st.tilesFilled);
    const double saved = all - double(st.tilesShaded);
    state.counters["decide_ns"] = saved > 0 ? (decided - plain * double(st.tilesShaded) / all) / saved * 1e9 : 0;
    state.counters["shade_ns"] = all > 0 ? plain / all * 1e9 : 0;
}

}  // namespace

BENCHMARK_CAPTURE(BM_FreshTargetRead, a8r8g8b8_cleared_1080p, D3DFMT_A8R8G8B8, true)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FreshTargetRead, x8r8g8b8_cleared_1080p, D3DFMT_X8R8G8B8, true)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FreshTargetRead, x8r8g8b8_partly_cleared_1080p, D3DFMT_X8R8G8B8, false)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FreshTargetRead, a16b16g16r16f_cleared_1080p, D3DFMT_A16B16G16R16F, true)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FreshTargetRead, r32f_cleared_1080p, D3DFMT_R32F, true)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_TileDecisions)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "blur"})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK(BM_Raster)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Draw, blur4_1080p_fx8, Pass::Blur4)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, copy_point_1080p_fx8, Pass::CopyPoint)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, copy_linear_1080p_fx8, Pass::CopyLinear)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_CAPTURE(BM_Draw, copy_linear_240x135_fx8, Pass::CopySmall)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, blur4_1x1_fx8, Pass::Tiny)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, down8_point_1080p_to_240x135_fx8, Pass::Down8Point)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, blur4_240x135_fx8, Pass::Blur4Small)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

BENCHMARK_CAPTURE(BM_Draw, weighted4_480x270_fx8, Pass::Weighted4)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, weighted4_480x270_fx8, Pass::Weighted4)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

BENCHMARK_CAPTURE(BM_Draw, composite_add_1080p_x4_fx8, Pass::CompositeAdd)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, composite_copy_1080p_x4_fx8, Pass::CompositeCopy)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, composite_putoff_1080p_x4_fx8, Pass::CompositePutOff)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, composite_screen_1080p_x8_fx8, Pass::Composite)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_CAPTURE(BM_AlignedVsQuads, blur4_1080p_fx8, Pass::Blur4)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, copy_linear_1080p_fx8, Pass::CopyLinear)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_Draw, sprites_400x64x64_1080p_fx8, Pass::Sprites)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, sprites_ffp_20x113_1080p_fx8, Pass::SpritesFfp)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Draw, sprites_ffp_1296x28_480x270_fx8, Pass::SpritesSmall)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, sprites_400x64x64_1080p_fx8, Pass::Sprites)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, copy_linear_240x135_fx8, Pass::CopySmall)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, down2_linear_1080p_to_960x540_fx8, Pass::Down2)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, down2_mip_1080p_to_960x540_fx8, Pass::Down2Mip)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, blur4_rotated_1080p_fx8, Pass::Rotated)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, copy_perspective_mip_1080p_fx8, Pass::PerspectiveMip)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, copy_perspective_trilinear_1080p_fx8, Pass::PerspectiveTrilinear)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, copy_perspective_1080p_fx8, Pass::Perspective)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, copy_projected_1080p_fx8, Pass::Projected)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, copy_texkill_half_1080p_fx8, Pass::Kill)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, dependent_1080p_fx12, Pass::Dependent)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();
BENCHMARK_CAPTURE(BM_AlignedVsQuads, down4_4tap_1080p_to_480x270_fx8, Pass::Down4)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

BENCHMARK_MAIN();
