// Random composites over a put-off copy (runner/random_composite.h).
#include "runner/random_composite.h"

#include <algorithm>
#include <cstring>
#include <random>
#include <sstream>

#include "emu/fullscreen.h"
#include "emu/resources.h"

namespace ps11test {

using namespace emu;

namespace {

// Programs that copy (all channels, or r g b with c0 = (1, 1, 1, 0)), shade, fill where the
// texture is zero, blend two taps, and fill everywhere; each is decided tile by tile in its own way.
const char* const kPrograms[] = {
    "ps_1_1\ntex t0\nmov r0, t0\n",
    "ps_1_1\ntex t0\nmul r0, t0, c0\n",
    "ps_1_1\ntex t0\nmul r0, t0, c1\n",
    "ps_1_1\ntex t0\nadd r0, t0, c2\n",
    "ps_1_1\ntex t0\ntex t1\nmad r0, t1, c1, t0\n",
    "ps_1_1\ntex t0\nmov r0, c2\n",
    "ps_1_1\ntex t0\nmad_sat r0, t0_bx2, c1, c2\n",
    "ps_1_1\ntex t0\ntex t1\nlrp r0, c1, t0, t1\n",
};

}  // namespace

std::string CompositeCase::describe() const {
    std::ostringstream s;
    s << width << "x" << height << ", texture " << texWidth << "x" << texHeight << ", "
      << (format == D3DFMT_X8R8G8B8 ? "X8R8G8B8" : "A8R8G8B8")
      << (sceneFormat != format ? " from the other format" : "") << ", "
      << (blend == 1   ? "ONE/ONE"
          : blend == 2 ? "SRCALPHA/INVSRCALPHA"
                       : "no blending")
      << (skip ? "" : ", no skipping") << (linear ? ", linear" : ", point") << ", " << ps11::precisionName(precision)
      << ", c1 = (" << constants[4] << ", " << constants[5] << ", " << constants[6] << ", " << constants[7]
      << "), c2 = (" << constants[8] << ", " << constants[9] << ", " << constants[10] << ", " << constants[11] << "), "
      << quads.size() << " quad(s):";
    for (const auto& q : quads)
        s << " [" << q[0] << ", " << q[1] << ") to [" << q[2] << ", " << q[3] << ") offset " << q[4] << " " << q[5]
          << ";";
    s << "\n" << program;
    return s.str();
}

CompositeCase randomComposite(const std::function<uint32_t()>& next) {
    auto uni = [&](int lo, int hi) { return lo + int(next() % uint32_t(hi - lo + 1)); };
    CompositeCase c;
    // Above kComparedResourceBytes (64 KB): sizes that end bands, tiles and vector groups anywhere.
    c.width = uint32_t(uni(170, 330)), c.height = uint32_t(uni(100, 140));
    static_assert(170 * 100 * 4 > emu::kComparedResourceBytes);
    const int scale = uni(0, 4) == 0 ? uni(1, 8) : 1 << uni(0, 3);
    c.texWidth = std::max(1u, c.width / uint32_t(scale)), c.texHeight = std::max(1u, c.height / uint32_t(scale));
    c.format = uni(0, 3) == 0 ? D3DFMT_X8R8G8B8 : D3DFMT_A8R8G8B8;
    c.sceneFormat = uni(0, 5) == 0 ? (c.format == D3DFMT_X8R8G8B8 ? D3DFMT_A8R8G8B8 : D3DFMT_X8R8G8B8) : c.format;
    c.program = kPrograms[uni(0, int(std::size(kPrograms)) - 1)];
    // c0 = (1, 1, 1, 0); c1 and c2 of 0, 1, a half or any byte (negative in c2 now and then).
    const float c0[4] = {1, 1, 1, 0};
    std::copy(c0, c0 + 4, c.constants.begin());
    for (int i = 4; i < 12; ++i) {
        const int kind = uni(0, 4);
        c.constants[size_t(i)] = kind == 0 ? 0.0f : kind == 1 ? 1.0f : kind == 2 ? 0.5f : float(uni(0, 255)) / 255.0f;
        if (i >= 8 && uni(0, 5) == 0) c.constants[size_t(i)] = -c.constants[size_t(i)];
    }
    const int blendKind = uni(0, 7);
    c.blend = blendKind < 5 ? 1 : blendKind < 7 ? 0 : 2;
    c.skip = uni(0, 2) != 0, c.linear = uni(0, 3) != 0;
    c.precision = uni(0, 4) == 0 ? ps11::Precision::Fx12 : ps11::Precision::Fx8;
    // The whole target, a part of it, or two overlapping quads; a texel offset now and then.
    const int w = int(c.width), h = int(c.height);
    const int shape = uni(0, 2);
    auto offset = [&](uint32_t texels) { return uni(0, 2) == 0 ? float(uni(-8, 8)) / (4.0f * float(texels)) : 0.0f; };
    if (shape == 1)
        c.quads.push_back({float(uni(0, w / 3)) + 0.3f, float(uni(0, h / 3)), float(uni(w / 2, w)) - 0.2f,
                           float(uni(h / 2, h)), offset(c.texWidth), offset(c.texHeight)});
    else
        c.quads.push_back({-0.5f, -0.5f, float(w) - 0.5f, float(h) - 0.5f, offset(c.texWidth), offset(c.texHeight)});
    if (shape == 2) c.quads.push_back({float(w) / 4, float(h) / 5, float(w) * 3 / 4, float(h) * 4 / 5, 0.0f, 0.0f});
    // The bytes, from an engine the next word seeds (a fuzzer's input steers the structure).
    std::mt19937 bytes(next());
    c.scene.resize(size_t(c.width) * c.height * 4);
    for (uint8_t& b : c.scene) b = uint8_t(bytes());
    // Blocks of zero (half of them), one constant or random texels, each what 2 by 2 tiles of 64
    // by 16 pixels read at this scale.
    c.texels.resize(size_t(c.texWidth) * c.texHeight * 4);
    const uint32_t bw = std::max(1u, 128u / uint32_t(scale)), bh = std::max(1u, 32u / uint32_t(scale));
    for (uint32_t by = 0; by < c.texHeight; by += bh)
        for (uint32_t bx = 0; bx < c.texWidth; bx += bw) {
            const int kind = std::max(0, uni(-1, 2));
            const uint32_t k = next();
            for (uint32_t y = by; y < std::min(c.texHeight, by + bh); ++y)
                for (uint32_t x = bx; x < std::min(c.texWidth, bx + bw); ++x)
                    for (uint32_t b = 0; b < 4; ++b)
                        c.texels[(size_t(y) * c.texWidth + x) * 4 + b] = kind == 0   ? 0
                                                                         : kind == 1 ? uint8_t(k >> (8 * b))
                                                                                     : uint8_t(bytes());
        }
    return c;
}

emu::DeviceOptions compositeDeviceOptions(ps11::Precision precision, bool skip, bool putOff, bool rowPaths) {
    emu::DeviceOptions o;
    o.precision = precision;
    o.software.threads = 2;
    o.software.putOffCopies = putOff;
    o.software.skipTiles = skip;
    o.software.timeTiles = false;
    o.software.alignedPasses = rowPaths;
    o.software.fastSampler = rowPaths;
    return o;
}

bool drawComposite(const CompositeCase& c, const emu::DeviceOptions& options, std::vector<uint8_t>& out,
                   std::string& error, bool* putOff) {
    using namespace emu;
    Device dev(options);
    auto ok = [&](HRESULT hr) {
        if (hr == D3D_OK) return true;
        error = dev.lastError().message.empty() ? "a device call failed" : dev.lastError().message;
        return false;
    };
    auto upload = [&](Handle h, UINT level, bool texture, const std::vector<uint8_t>& bytes, uint32_t w, uint32_t hh) {
        D3DLOCKED_RECT lr{};
        if (!ok(texture ? dev.LockRect(h, level, &lr, nullptr, 0) : dev.LockRect(h, &lr, nullptr, 0))) return false;
        for (uint32_t y = 0; y < hh; ++y)
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * uint32_t(lr.Pitch), &bytes[size_t(y) * w * 4], w * 4);
        return ok(texture ? dev.UnlockRect(h, level) : dev.UnlockRect(h));
    };
    Handle src{}, target{}, tex{}, ps{};
    if (!ok(dev.CreateRenderTarget(c.width, c.height, c.sceneFormat, 1, &src)) ||
        !ok(dev.CreateRenderTarget(c.width, c.height, c.format, 1, &target)) ||
        !ok(dev.CreateTexture(c.texWidth, c.texHeight, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex)) ||
        !upload(src, 0, false, c.scene, c.width, c.height) ||
        !upload(tex, 0, true, c.texels, c.texWidth, c.texHeight) ||
        !ok(dev.CreatePixelShaderFromText(c.program.c_str(), &ps)) || !ok(dev.SetPixelShader(ps)) ||
        !ok(dev.SetPixelShaderConstantF(0, c.constants.data(), 3)))
        return false;
    for (DWORD s = 0; s < 2; ++s) {
        if (!ok(dev.SetTexture(s, tex))) return false;
        for (D3DSAMPLERSTATETYPE f : {D3DSAMP_MINFILTER, D3DSAMP_MAGFILTER})
            if (!ok(dev.SetSamplerState(s, f, c.linear ? D3DTEXF_LINEAR : D3DTEXF_POINT))) return false;
    }
    const D3DBLEND srcBlend = c.blend == 2 ? D3DBLEND_SRCALPHA : D3DBLEND_ONE;
    const D3DBLEND dstBlend = c.blend == 2 ? D3DBLEND_INVSRCALPHA : D3DBLEND_ONE;
    if (!ok(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, c.blend != 0 ? 1 : 0)) ||
        !ok(dev.SetRenderState(D3DRS_SRCBLEND, srcBlend)) || !ok(dev.SetRenderState(D3DRS_DESTBLEND, dstBlend)) ||
        !ok(dev.SetRenderTarget(0, target)) || !ok(dev.SetFVF(kQuadFvf)))
        return false;
    // Each quad maps the target's pixels 1:1 onto the texture's extent, shifted by its offset.
    std::vector<QuadVertex> v;
    const float w = float(c.width), h = float(c.height);
    for (const auto& q : c.quads) {
        const float tu = (q[2] - q[0]) / w, tv = (q[3] - q[1]) / h;
        const float u0 = (q[0] + 0.5f) / w + q[4], v0 = (q[1] + 0.5f) / h + q[5];
        const auto corners =
            halfPixelQuad(q[0] + 0.5f, q[1] + 0.5f, q[2] + 0.5f, q[3] + 0.5f,
                          {QuadCoords{u0, v0, u0 + tu, v0 + tv}, QuadCoords{u0 + 0.01f, v0, u0 + tu + 0.01f, v0 + tv},
                           QuadCoords{}, QuadCoords{}});
        for (int k : {0, 1, 2, 2, 1, 3}) v.push_back(corners[size_t(k)]);
    }
    out.clear();
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 0) {
            if (!ok(dev.StretchRect(src, nullptr, target, nullptr, D3DTEXF_POINT))) return false;
            if (putOff) *putOff = dev.lastStretchPutOff();
        }
        if (!ok(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(v.size() / 3), v.data(), sizeof(QuadVertex))))
            return false;
        D3DLOCKED_RECT lr{};
        if (!ok(dev.LockRect(target, &lr, nullptr, D3DLOCK_READONLY))) return false;
        for (uint32_t y = 0; y < c.height; ++y) {
            const uint8_t* row = static_cast<const uint8_t*>(lr.pBits) + y * uint32_t(lr.Pitch);
            out.insert(out.end(), row, row + size_t(c.width) * 4);
        }
        if (!ok(dev.UnlockRect(target))) return false;
    }
    return true;
}

}  // namespace ps11test
