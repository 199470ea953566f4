// BM_EmuVsGl: the emulator's speed against its peer, the GL renderer's native mode on Mesa
// llvmpipe (PERF.md "The peer"), in one process. Every pass runs on four emu::Devices: the
// software renderer (2 worker threads) in the 1.1-class card's fx8 and in `ideal`, and the GL
// renderer (LP_NUM_THREADS=2 unless set; OSMesa, or EGL with PS11_GL=egl) in native mode and in exact mode, registered emu_fx8,
// emu_ideal, gl_native, gl_exact, … so that --benchmark_enable_random_interleaving mixes their
// repetitions under the same machine load. Each reports the wall time of DrawPrimitiveUP followed
// by Device::finish (GL's work done); the GL devices keep their surfaces resident, so nothing is
// uploaded or read back per draw. Before any timing, each pass is drawn once on every device:
// emu_fx8 and gl_exact must agree byte for byte; gl_native's distance from emu_fx8 is reported
// (`native_max_diff`).
// How to run and read the ratios: bench/README.md "bench_emu_vs_gl".
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "bench/bench_shaders.h"
#include "emu/device.h"
#include "emu/fullscreen.h"
#include "emu/gl/gl_renderer.h"
#include "runner/gl_backend.h"

namespace {

using bench::kBlur4;
using bench::kCopy;

using namespace emu;

constexpr UINT kW = 1920, kH = 1080;

// Scene (t0, 1:1) plus the magnified half-size bloom (t1) scaled by c0 = 0.5.
constexpr const char* kComposite =
    "ps_1_1\n"
    "tex t0\n"
    "tex t1\n"
    "mad r0, t1, c0, t0\n";

// A dependent read, ps_1_1's own: t1 sampled where t0's red and green, through stage 1's bump
// matrix, move its coordinates (texbem). The row paths' pre-sampled runs execute it, each lane
// sampled where the program puts it (docs/device.md "Aligned passes").
constexpr const char* kBump =
    "ps_1_1\n"
    "tex t0\n"
    "texbem t1, t0\n"
    "mov r0, t1\n";

// texkill on stage 0's coordinates (shifted so the quad's left quarter is killed), then a read.
constexpr const char* kKill =
    "ps_1_1\n"
    "texkill t0\n"
    "tex t1\n"
    "mov r0, t1\n";

// Coordinates as a colour (texcoord: saturated u v w, 1) times a read.
constexpr const char* kTexcoord =
    "ps_1_1\n"
    "texcoord t0\n"
    "tex t1\n"
    "mul r0, t0, t1\n";

enum class Pass { Blur4, Copy, Down2, Down4, Magnify2Composite, Blur4Rotated, Bump, BumpMip, Kill, Texcoord };
constexpr int kPasses = 10;
enum class Kind { EmuFx8, EmuIdeal, GlNative, GlExact };
constexpr Kind kKinds[] = {Kind::EmuFx8, Kind::EmuIdeal, Kind::GlNative, Kind::GlExact};
const char* kindName(Kind k) {
    switch (k) {
        case Kind::EmuFx8:
            return "emu_fx8";
        case Kind::EmuIdeal:
            return "emu_ideal";
        case Kind::GlNative:
            return "gl_native";
        case Kind::GlExact:
            return "gl_exact";
    }
    return "";
}
bool isGl(Kind k) { return k == Kind::GlNative || k == Kind::GlExact; }

struct StageDef {
    int texture;     // index into PassDef::textures
    float du, dv;    // tap offset in texels of that texture
};

struct PassDef {
    const char* name;
    UINT w, h;                                   // render target
    std::vector<std::pair<UINT, UINT>> textures;  // sizes; texture i is filled with seed 42 + i
    std::vector<StageDef> stages;
    const char* shader;
    float c0;
    float turn = 0;  // texture coordinates turned by this many degrees about the centre
    float bump = 0;  // stage 1's bump matrix: (bump, 0; 0, bump)
    int mipTexture = -1;  // this texture gets its whole chain (AUTOGENMIPMAP), read with MIP filter LINEAR
};

PassDef passDef(Pass p) {
    switch (p) {
    case Pass::Blur4:  // taps at (±½, ±½) texel: each averages a 2×2 block
        return {"blur4_1080p", kW, kH, {{kW, kH}}, {{0, -0.5f, -0.5f}, {0, 0.5f, -0.5f}, {0, -0.5f, 0.5f}, {0, 0.5f, 0.5f}},
                kBlur4, 0.25f};
    case Pass::Copy:  // bilinear at the texel centres
        return {"copy_1080p", kW, kH, {{kW, kH}}, {{0, 0, 0}}, kCopy, 0};
    case Pass::Down2:  // one tap on the corner shared by each 2×2 block
        return {"down2_1080p", kW / 2, kH / 2, {{kW, kH}}, {{0, 0, 0}}, kCopy, 0};
    case Pass::Down4:  // taps at ±1 texel around the centre of each 4×4 block
        return {"down4_1080p", kW / 4, kH / 4, {{kW, kH}}, {{0, -1, -1}, {0, 1, -1}, {0, -1, 1}, {0, 1, 1}}, kBlur4, 0.25f};
    case Pass::Blur4Rotated:  // the blur with its coordinates turned by 10°: sampled per pixel
        return {"blur4_rotated_1080p",
                kW,
                kH,
                {{kW, kH}},
                {{0, -0.5f, -0.5f}, {0, 0.5f, -0.5f}, {0, -0.5f, 0.5f}, {0, 0.5f, 0.5f}},
                kBlur4,
                0.25f,
                10.0f};
    case Pass::Magnify2Composite:  // t0 1:1 at 1080p, t1 a 960×540 texture magnified 2×
        return {"magnify2_composite_1080p", kW, kH, {{kW, kH}, {kW / 2, kH / 2}}, {{0, 0, 0}, {1, 0, 0}}, kComposite, 0.5f};
    case Pass::Bump:  // t1 moved by up to 0.03 of its size by t0 (texbem)
        return {"bump_1080p", kW, kH, {{kW, kH}, {kW, kH}}, {{0, 0, 0}, {1, 0, 0}}, kBump, 0, 0, 0.03f};
    case Pass::BumpMip:  // the same over a mip-mapped t1: each quad's level from its moved coordinates
        return {"bump_mip_1080p", kW, kH, {{kW, kH}, {kW, kH}}, {{0, 0, 0}, {1, 0, 0}}, kBump, 0, 0, 0.03f, 1};
    case Pass::Kill:  // stage 0's u runs from −0.25, so a quarter of the pixels are killed
        return {"texkill_1080p", kW, kH, {{kW, kH}, {kW, kH}}, {{0, -480, 0}, {1, 0, 0}}, kKill, 0};
    case Pass::Texcoord:
        return {"texcoord_1080p", kW, kH, {{kW, kH}, {kW, kH}}, {{0, 0, 0}, {1, 0, 0}}, kTexcoord, 0};
    }
    return {};
}

// One device drawing one pass, its state set once. Never destroyed (see scene()).
struct Scene {
    std::unique_ptr<Device> dev;
    Handle rt{};
    std::vector<float> vertices;
    UINT stride = 0;
    std::string error;  // empty: ready

    Scene(Pass pass, Kind kind) { setup(pass, kind); }
    void setup(Pass pass, Kind kind);
    bool draw() {
        const bool ok = dev->DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, vertices.data(), stride) == D3D_OK;
        dev->finish();
        return ok;
    }
    // The render target's bytes (rows packed), or empty with `error` set.
    std::vector<uint8_t> image();
};

std::string glError;  // why no GL renderer could be made (first failure)

void Scene::setup(Pass pass, Kind kind) {
    const PassDef pd = passDef(pass);
    DeviceOptions o;
    o.software.threads = 2;
    if (kind == Kind::EmuIdeal) o.precision = ps11::Precision::Ideal;
    if (isGl(kind)) {
        // llvmpipe reads its thread count when the context's screen is made.
        setenv("LP_NUM_THREADS", "2", 0);
        std::string why;
        const char* glKind = std::getenv("PS11_GL");  // "egl" for a GPU driver
        o.renderer = ps11test::glRendererFactory(glKind ? glKind : "osmesa", why, kind == Kind::GlNative);
        if (!o.renderer) {
            error = why;
            if (glError.empty()) glError = error;
            return;
        }
    }
    dev = std::make_unique<Device>(o);
    auto refused = [&](const char* call) {
        error = std::string(call) + " refused: " + dev->lastError().message;
    };
    if (dev->CreateRenderTarget(pd.w, pd.h, D3DFMT_A8R8G8B8, 0, &rt) != D3D_OK) return refused("CreateRenderTarget");
    if (dev->SetRenderTarget(0, rt) != D3D_OK) return refused("SetRenderTarget");
    std::vector<Handle> textures;
    for (size_t i = 0; i < pd.textures.size(); ++i) {
        const auto [tw, th] = pd.textures[i];
        Handle tex{};
        const bool mips = int(i) == pd.mipTexture;
        if (dev->CreateTexture(tw, th, mips ? 0 : 1, mips ? D3DUSAGE_AUTOGENMIPMAP : 0, D3DFMT_A8R8G8B8,
                               D3DPOOL_MANAGED, &tex) != D3D_OK)
            return refused("CreateTexture");
        D3DLOCKED_RECT lr;
        if (dev->LockRect(tex, 0, &lr, nullptr, 0) != D3D_OK) return refused("LockRect");
        std::mt19937 rng(uint32_t(42 + i));
        for (UINT y = 0; y < th; ++y) {
            auto* row = reinterpret_cast<uint32_t*>(static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch));
            for (UINT x = 0; x < tw; ++x) row[x] = rng();
        }
        dev->UnlockRect(tex, 0);
        if (mips && dev->GenerateMipSubLevels(tex) != D3D_OK) return refused("GenerateMipSubLevels");
        textures.push_back(tex);
    }
    for (size_t s = 0; s < pd.stages.size(); ++s) {
        const DWORD st = DWORD(s);
        dev->SetTexture(st, textures[size_t(pd.stages[s].texture)]);
        dev->SetSamplerState(st, D3DSAMP_MINFILTER, D3DTEXF_LINEAR);
        dev->SetSamplerState(st, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR);
        dev->SetSamplerState(st, D3DSAMP_ADDRESSU, D3DTADDRESS_CLAMP);
        dev->SetSamplerState(st, D3DSAMP_ADDRESSV, D3DTADDRESS_CLAMP);
        if (pd.stages[s].texture == pd.mipTexture) dev->SetSamplerState(st, D3DSAMP_MIPFILTER, D3DTEXF_LINEAR);
    }
    if (pd.bump != 0) {
        DWORD m;
        std::memcpy(&m, &pd.bump, sizeof m);
        if (dev->SetTextureStageState(1, D3DTSS_BUMPENVMAT00, m) != D3D_OK ||
            dev->SetTextureStageState(1, D3DTSS_BUMPENVMAT11, m) != D3D_OK)
            return refused("SetTextureStageState");
    }
    Handle ps{};
    if (dev->CreatePixelShaderFromText(pd.shader, &ps) != D3D_OK) return refused("CreatePixelShaderFromText");
    if (dev->SetPixelShader(ps) != D3D_OK) return refused("SetPixelShader");
    const float c0[4] = {pd.c0, pd.c0, pd.c0, pd.c0};
    dev->SetPixelShaderConstantF(0, c0, 1);
    const UINT sets = UINT(pd.stages.size());
    if (dev->SetFVF(D3DFVF_XYZRHW | (sets << D3DFVF_TEXCOUNT_SHIFT)) != D3D_OK) return refused("SetFVF");
    // The half-pixel quad (corners at −0.5), uv 0..1 over the target plus each stage's offset.
    const float xs[4] = {-0.5f, float(pd.w) - 0.5f, float(pd.w) - 0.5f, -0.5f};
    const float ys[4] = {-0.5f, -0.5f, float(pd.h) - 0.5f, float(pd.h) - 0.5f};
    const float us[4] = {0, 1, 1, 0}, vs[4] = {0, 0, 1, 1};
    stride = UINT(sizeof(float)) * (4 + 2 * sets);
    const float turn = pd.turn * 3.14159265f / 180.0f;
    for (int c : {0, 1, 2, 0, 2, 3}) {
        vertices.insert(vertices.end(), {xs[c], ys[c], 0.0f, 1.0f});
        const float u = 0.5f + std::cos(turn) * (us[c] - 0.5f) - std::sin(turn) * (vs[c] - 0.5f);
        const float v = 0.5f + std::sin(turn) * (us[c] - 0.5f) + std::cos(turn) * (vs[c] - 0.5f);
        for (const StageDef& sd : pd.stages) {
            const auto [tw, th] = pd.textures[size_t(sd.texture)];
            vertices.push_back(u + sd.du / float(tw));
            vertices.push_back(v + sd.dv / float(th));
        }
    }
    // Warm-up: the sampler's copy of the textures, the executor or the GL program and textures.
    if (!draw()) return refused("DrawPrimitiveUP");
}

std::vector<uint8_t> Scene::image() {
    std::optional<SurfacePixels> px = readSurface(*dev, rt, error);
    if (!px) {
        error = "read-back refused: " + error;
        return {};
    }
    return std::move(px->bytes);
}

struct PassScenes {
    Scene* scenes[4] = {};  // by Kind
    std::string mismatch;   // non-empty: emu_fx8 and gl_exact differ (or could not be compared)
    int nativeMaxDiff = -1;  // gl_native against emu_fx8, 8-bit levels
};

// Both devices of a pass, made on first use and compared once. Never destroyed: at exit,
// libOSMesa's own state may be gone before a static destructor would release a context
// (runner/gl_backend.cpp).
PassScenes& scenes(Pass pass) {
    static PassScenes* all = new PassScenes[kPasses];
    PassScenes& p = all[int(pass)];
    if (!p.scenes[0]) {
        for (Kind k : kKinds) p.scenes[int(k)] = new Scene(pass, k);
        Scene& fx8 = *p.scenes[int(Kind::EmuFx8)];
        Scene& exact = *p.scenes[int(Kind::GlExact)];
        Scene& native = *p.scenes[int(Kind::GlNative)];
        if (fx8.error.empty() && exact.error.empty() && native.error.empty()) {
            const std::vector<uint8_t> a = fx8.image(), b = exact.image(), c = native.image();
            if (a.empty() || b.empty() || c.empty())
                p.mismatch = "read-back failed: " + fx8.error + exact.error + native.error;
            else {
                size_t differ = 0;
                for (size_t i = 0; i < a.size(); i += 4) differ += std::memcmp(&a[i], &b[i], 4) != 0;
                if (differ) p.mismatch = "emu_fx8 and gl_exact images differ: " + std::to_string(differ) + " pixels";
                p.nativeMaxDiff = 0;
                for (size_t i = 0; i < a.size(); ++i) p.nativeMaxDiff = std::max(p.nativeMaxDiff, std::abs(int(a[i]) - int(c[i])));
            }
        }
    }
    return p;
}

void BM_EmuVsGl(benchmark::State& state, Pass pass, Kind kind) {
    PassScenes& ps = scenes(pass);
    Scene& sc = *ps.scenes[int(kind)];
    if (!sc.error.empty()) {
        state.SkipWithError(sc.error.c_str());
        return;
    }
    if (!ps.mismatch.empty()) {
        state.SkipWithError(ps.mismatch.c_str());
        return;
    }
    double drawSum = 0;
    const emu::TransferStats before = sc.dev->transfers();
    for (auto _ : state) {
        const auto t0 = std::chrono::steady_clock::now();
        const bool ok = sc.draw();
        const double draw = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (!ok) {
            state.SkipWithError(sc.dev->lastError().message.c_str());
            return;
        }
        state.SetIterationTime(draw);
        drawSum += draw;
    }
    const emu::TransferStats after = sc.dev->transfers();
    const PassDef pd = passDef(pass);
    const double n = double(std::max<benchmark::IterationCount>(state.iterations(), 1));
    const double pixels = double(pd.w) * pd.h;
    state.counters["Mpix/s"] = drawSum > 0 ? pixels * n / drawSum * 1e-6 : 0;
    // Surfaces crossing per draw (0 once resident) and the native mode's distance from fx8.
    state.counters["uploads"] = double(after.uploads - before.uploads) / n;
    state.counters["readbacks"] = double(after.readBacks - before.readBacks) / n;
    if (kind == Kind::GlNative) state.counters["native_max_diff"] = ps.nativeMaxDiff;
    state.SetLabel(isGl(kind) ? ps11test::glRendererDescription() : "software, 2 threads");
}

}  // namespace

int main(int argc, char** argv) {
    // The four devices of each pass registered alternately.
    for (Pass p : {Pass::Blur4, Pass::Copy, Pass::Down2, Pass::Down4, Pass::Magnify2Composite, Pass::Blur4Rotated,
                   Pass::Bump, Pass::BumpMip, Pass::Kill, Pass::Texcoord})
        for (Kind k : kKinds) {
            const std::string name = std::string("BM_EmuVsGl/") + passDef(p).name + "/" + kindName(k);
            benchmark::RegisterBenchmark(name.c_str(), BM_EmuVsGl, p, k)
                ->Unit(benchmark::kMillisecond)
                ->UseManualTime();
        }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
