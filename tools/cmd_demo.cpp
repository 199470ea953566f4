// `ps11 demo`, the device half: the classic three-pass bloom of the D3D8/9 era, written with
// the corpus's ps_1_1 shaders (bloom_brightpass, bloom_blur4, bloom_composite) and drawn on
// emu::Device exactly as a D3D9 program would: a procedural scene texture, half-size render
// target textures, half-pixel-shifted quads, bilinear taps. Each profile renders the same
// frame on each hardware class (ps11/hardware.h), after an `ideal` reference; the table shows
// each pass's time (median of the runs) and how far the final image is from the reference, in
// 8-bit levels.
#include "tools/cmd_demo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "emu/device.h"
#include "ps11/assembler.h"
#include "ps11/encoder.h"
#include "ps11/validator.h"
#include "tools/cli_util.h"

namespace ps11 {
namespace {

using namespace emu;

struct QuadVertex {
    float x, y, z, rhw;
    DWORD diffuse, specular;
    float tex[4][2];
};
constexpr DWORD kQuadFvf = D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_SPECULAR | D3DFVF_TEX4;

// The procedural scene: a sky gradient over a checkered ground with three bright lights, the
// parts above the bright pass's threshold.
std::vector<uint32_t> makeScene(uint32_t w, uint32_t h) {
    std::vector<uint32_t> argb(size_t(w) * h);
    struct Light {
        float x, y, r;
        uint32_t rgb;
    };
    const Light lights[] = {{0.25f, 0.30f, 0.05f, 0xffffff}, {0.70f, 0.20f, 0.03f, 0xffdc96}, {0.55f, 0.75f, 0.04f, 0xc8ffff}};
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float fy = float(y) / float(h);
            uint32_t r, g, b;
            if (fy < 0.6f) {
                r = uint32_t(40 + 60 * fy);
                g = uint32_t(70 + 80 * fy);
                b = uint32_t(160 + 60 * (1 - fy));
            } else {
                const bool dark = ((x / 24) + (y / 24)) & 1;
                r = dark ? 60 : 90;
                g = dark ? 80 : 110;
                b = dark ? 50 : 70;
            }
            for (const Light& l : lights) {
                const float dx = float(x) - l.x * float(w), dy = float(y) - l.y * float(h);
                if (dx * dx + dy * dy <= (l.r * float(h)) * (l.r * float(h))) {
                    r = (l.rgb >> 16) & 0xff;
                    g = (l.rgb >> 8) & 0xff;
                    b = l.rgb & 0xff;
                }
            }
            argb[size_t(y) * w + x] = 0xff000000u | r << 16 | g << 8 | b;
        }
    return argb;
}

// A full-target quad shifted by half a pixel (docs/test-format.md `draw quad`), texture
// coordinate set i covering (0,0)-(1,1) moved by offsets[i] (in units of the texture).
std::array<QuadVertex, 4> quad(uint32_t w, uint32_t h, const std::array<std::array<float, 2>, 4>& offsets) {
    std::array<QuadVertex, 4> v{};
    for (int i = 0; i < 4; ++i) {
        const int cx = i & 1, cy = i >> 1;
        v[size_t(i)] = {cx ? float(w) - 0.5f : -0.5f, cy ? float(h) - 0.5f : -0.5f, 0, 1, 0xffffffff, 0, {}};
        for (int t = 0; t < 4; ++t) {
            v[size_t(i)].tex[t][0] = float(cx) + offsets[size_t(t)][0];
            v[size_t(i)].tex[t][1] = float(cy) + offsets[size_t(t)][1];
        }
    }
    return v;
}

struct PassTimes {
    double bright = 0, blur = 0, composite = 0;
};

class BloomRun {
public:
    BloomRun(const HardwareClass* hardware, std::optional<Precision> p, const BloomDemoOptions& o,
             const std::array<std::vector<uint32_t>, 3>& shaders, const std::vector<uint32_t>& scene)
        : m_options(o), m_shaders(shaders), m_scene(scene) {
        DeviceOptions d;
        d.hardware = hardware;
        d.precision = p;
        d.software.threads = o.threads;
        m_device = std::make_unique<Device>(d);
    }

    // Sets up the resources; false (with the device's message printed) on failure.
    bool setUp() {
        Device& d = *m_device;
        const uint32_t w = m_options.width, h = m_options.height, hw = std::max(w / 2, 1u), hh = std::max(h / 2, 1u);
        if (!check(d.CreateTexture(w, h, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &m_sceneTex))) return false;
        D3DLOCKED_RECT locked;
        if (!check(d.LockRect(m_sceneTex, 0, &locked, nullptr, 0))) return false;
        for (uint32_t y = 0; y < h; ++y)
            std::memcpy(static_cast<uint8_t*>(locked.pBits) + size_t(y) * size_t(locked.Pitch), &m_scene[size_t(y) * w],
                        size_t(w) * 4);
        if (!check(d.UnlockRect(m_sceneTex, 0))) return false;
        for (Handle* t : {&m_brightTex, &m_blurTex})
            if (!check(d.CreateTexture(hw, hh, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, t)))
                return false;
        if (!check(d.GetSurfaceLevel(m_brightTex, 0, &m_brightSurf)) ||
            !check(d.GetSurfaceLevel(m_blurTex, 0, &m_blurSurf)) ||
            !check(d.CreateRenderTarget(w, h, D3DFMT_A8R8G8B8, 0, &m_final)))
            return false;
        for (int i = 0; i < 3; ++i)
            if (!check(d.CreatePixelShader(std::span<const DWORD>(m_shaders[size_t(i)]), &m_ps[size_t(i)])))
                return false;
        for (DWORD s = 0; s < 4; ++s)
            if (!check(d.SetSamplerState(s, D3DSAMP_ADDRESSU, D3DTADDRESS_CLAMP)) ||
                !check(d.SetSamplerState(s, D3DSAMP_ADDRESSV, D3DTADDRESS_CLAMP)) ||
                !check(d.SetSamplerState(s, D3DSAMP_MINFILTER, D3DTEXF_LINEAR)) ||
                !check(d.SetSamplerState(s, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR)))
                return false;
        return check(d.SetFVF(kQuadFvf));
    }

    // One frame: bright pass (scene → half size, each pixel a bilinear 2x2 average), 4-tap
    // blur at the texel corners (a 3x3 tent), composite at full size.
    bool frame(PassTimes& t) {
        Device& d = *m_device;
        const uint32_t w = m_options.width, h = m_options.height, hw = std::max(w / 2, 1u), hh = std::max(h / 2, 1u);
        const std::array<std::array<float, 2>, 4> none{};
        if (!check(d.SetRenderTarget(0, m_brightSurf)) || !check(d.SetPixelShader(m_ps[0])) ||
            !check(d.SetTexture(0, m_sceneTex)) || !draw(quad(hw, hh, none)))
            return false;
        t.bright = d.lastDrawStats().milliseconds;

        const float du = 0.5f / float(hw), dv = 0.5f / float(hh);
        const std::array<std::array<float, 2>, 4> taps{{{-du, -dv}, {du, -dv}, {-du, dv}, {du, dv}}};
        if (!check(d.SetRenderTarget(0, m_blurSurf)) || !check(d.SetPixelShader(m_ps[1])))
            return false;
        for (DWORD s = 0; s < 4; ++s)
            if (!check(d.SetTexture(s, m_brightTex))) return false;
        if (!draw(quad(hw, hh, taps))) return false;
        t.blur = d.lastDrawStats().milliseconds;

        if (!check(d.SetRenderTarget(0, m_final)) || !check(d.SetPixelShader(m_ps[2])) ||
            !check(d.SetTexture(0, m_sceneTex)) || !check(d.SetTexture(1, m_blurTex)) ||
            !check(d.SetTexture(2, Handle::Null)) || !check(d.SetTexture(3, Handle::Null)) ||
            !draw(quad(w, h, none)))
            return false;
        t.composite = d.lastDrawStats().milliseconds;
        return true;
    }

    // The final image as 0xAARRGGBB words.
    bool readBack(std::vector<uint32_t>& out) {
        Device& d = *m_device;
        const uint32_t w = m_options.width, h = m_options.height;
        Handle copy{};
        D3DLOCKED_RECT locked;
        if (!check(d.CreateOffscreenPlainSurface(w, h, D3DFMT_A8R8G8B8, D3DPOOL_SYSTEMMEM, &copy)) ||
            !check(d.GetRenderTargetData(m_final, copy)) || !check(d.LockRect(copy, &locked, nullptr, D3DLOCK_READONLY)))
            return false;
        out.resize(size_t(w) * h);
        for (uint32_t y = 0; y < h; ++y)
            std::memcpy(&out[size_t(y) * w], static_cast<const uint8_t*>(locked.pBits) + size_t(y) * size_t(locked.Pitch),
                        size_t(w) * 4);
        d.UnlockRect(copy);
        d.Release(copy);
        return true;
    }

    const HardwareConfig& hardware() const { return m_device->hardware(); }

private:
    bool check(HRESULT hr) {
        if (hr == D3D_OK) return true;
        std::fprintf(stderr, "ps11: demo: %s\n", m_device->lastError().message.c_str());
        return false;
    }
    bool draw(const std::array<QuadVertex, 4>& v) {
        return check(m_device->DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, v.data(), sizeof(QuadVertex)));
    }

    BloomDemoOptions m_options;
    const std::array<std::vector<uint32_t>, 3>& m_shaders;
    const std::vector<uint32_t>& m_scene;
    std::unique_ptr<Device> m_device;
    Handle m_sceneTex{}, m_brightTex{}, m_blurTex{}, m_brightSurf{}, m_blurSurf{}, m_final{};
    std::array<Handle, 3> m_ps{};
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

bool writePpm(const std::string& path, const std::vector<uint32_t>& argb, uint32_t w, uint32_t h) {
    std::string bytes = "P6\n" + std::to_string(w) + " " + std::to_string(h) + "\n255\n";
    bytes.reserve(bytes.size() + argb.size() * 3);
    for (uint32_t p : argb) {
        bytes += char((p >> 16) & 0xff);
        bytes += char((p >> 8) & 0xff);
        bytes += char(p & 0xff);
    }
    return cli::writeFile(path, bytes);
}

}  // namespace

int runBloomDemo(const std::string& projectDir, const BloomDemoOptions& o) {
    const char* names[3] = {"bloom_brightpass", "bloom_blur4", "bloom_composite"};
    std::array<std::vector<uint32_t>, 3> shaders;
    for (int i = 0; i < 3; ++i) {
        const std::string path = projectDir + "/tests/shaders/corpus/ps_1_1/" + names[i] + ".psh";
        std::optional<std::string> text = cli::readFile(path);
        if (!text) return cli::kUserError;
        Diagnostics diags;
        std::optional<Program> program = parseAssembly(*text, path, AssembleOptions{}, diags);
        if (program) validate(*program, diags);
        if (!program || diags.hasErrors()) {
            std::fprintf(stderr, "%s", diags.formatAll().c_str());
            return cli::kUserError;
        }
        shaders[size_t(i)] = encode(*program);
    }
    const std::vector<uint32_t> scene = makeScene(o.width, o.height);
    std::printf("bloom on the emu device: %ux%u scene, bright pass and 4-tap blur at %ux%u, composite at %ux%u\n",
                o.width, o.height, std::max(o.width / 2, 1u), std::max(o.height / 2, 1u), o.width, o.height);
    std::printf("(corpus shaders ps_1_1/bloom_*.psh; times are medians of %d frames; error = final image vs ideal, "
                "in 8-bit levels)\n\n",
                o.repeats);
    std::printf("%-11s %-8s %9s %9s %12s %9s %8s %9s %10s\n", "hardware", "profile", "bright", "blur", "composite",
                "frame", "max err", "mean err", "differing");

    // The reference first: the default class with the ideal profile; then every class (or the
    // one asked for) with its own profile and MaxValue.
    struct Row {
        const HardwareClass* hardware;
        std::optional<Precision> precision;
    };
    std::vector<Row> rows{{nullptr, Precision::Ideal}};
    for (const HardwareClass& h : hardwareClasses())
        if (!o.hardware || o.hardware == &h) rows.push_back({&h, std::nullopt});
    std::vector<uint32_t> reference;
    for (const Row& row : rows) {
        BloomRun run(row.hardware, row.precision, o, shaders, scene);
        const HardwareConfig& hw = run.hardware();
        const Precision p = hw.precision;
        if (!run.setUp()) return cli::kUserError;
        std::vector<double> bright, blur, composite, frame;
        for (int r = 0; r < std::max(o.repeats, 1); ++r) {
            PassTimes t;
            if (!run.frame(t)) return cli::kUserError;
            bright.push_back(t.bright);
            blur.push_back(t.blur);
            composite.push_back(t.composite);
            frame.push_back(t.bright + t.blur + t.composite);
        }
        std::vector<uint32_t> image;
        if (!run.readBack(image)) return cli::kUserError;
        if (reference.empty()) reference = image;
        int maxErr = 0;
        uint64_t sumErr = 0, differing = 0;
        for (size_t i = 0; i < image.size(); ++i) {
            int worst = 0;
            for (int shift : {0, 8, 16, 24}) {
                const int e = std::abs(int((image[i] >> shift) & 0xff) - int((reference[i] >> shift) & 0xff));
                worst = std::max(worst, e);
                sumErr += uint64_t(e);
            }
            maxErr = std::max(maxErr, worst);
            differing += worst != 0;
        }
        const double mean = image.empty() ? 0 : double(sumErr) / double(image.size() * 4);
        char diff[32];
        std::snprintf(diff, sizeof diff, "%.2f%%", image.empty() ? 0 : 100.0 * double(differing) / double(image.size()));
        const std::string name = row.hardware ? std::string(hw.hardware->name) : "reference";
        std::printf("%-11s %-8s %7.2fms %7.2fms %10.2fms %7.2fms %8d %9.4f %10s\n", name.c_str(), precisionName(p),
                    median(bright), median(blur), median(composite), median(frame), maxErr, mean, diff);
        if (!o.outPrefix.empty()) {
            const std::string path = o.outPrefix + "-" + name + ".ppm";
            if (!writePpm(path, image, o.width, o.height)) return cli::kUserError;
        }
    }
    return cli::kOk;
}

}  // namespace ps11
