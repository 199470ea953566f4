// `ps11 test`, the device part: a .ps11test's sections as D3D9 calls on emu::Device, its draws
// as DrawPrimitiveUP and its pixel probes against the read-back render target
// (docs/test-format.md).
#include "runner/test_draw.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <variant>

#include "emu/device.h"
#include "emu/format.h"
#include "ps11/encoder.h"

namespace ps11test {

using namespace ps11;
namespace {

// D3D9 names (D3DRS_*, D3DFMT_*, …) live in namespace emu.
using namespace emu;

std::string where(const std::string& path, uint32_t line) {
    return line ? path + ":" + std::to_string(line) : path;
}

// "FILE:LINE: <call> failed: E41xx …" from the device's last error.
std::string refused(const Device& device, const std::string& path, uint32_t line, const char* what) {
    // The device's messages name the call and the argument already.
    const std::string& message = device.lastError().message;
    return where(path, line) + ": " + (message.empty() ? std::string(what) + " failed" : message);
}

// A colour as a D3DCOLOR: the word as written, or floats rounded to bytes.
D3DCOLOR argbOf(const Color& c) {
    if (c.packed) return c.argb;
    auto byte = [](float v) {
        float x = std::nearbyint(std::fmin(std::fmax(v, 0.0f), 1.0f) * 255.0f);
        return uint32_t(x);
    };
    return byte(c.rgba[3]) << 24 | byte(c.rgba[0]) << 16 | byte(c.rgba[1]) << 8 | byte(c.rgba[2]);
}

DWORD argValue(const TextureArg& a) {
    return DWORD(a.source) | (a.complement ? D3DTA_COMPLEMENT : 0u) | (a.alphaReplicate ? D3DTA_ALPHAREPLICATE : 0u) |
           a.otherBits;
}

D3DMATRIX matrixOf(const Matrix4& m) {
    D3DMATRIX d;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) d.m[r][c] = m[size_t(r * 4 + c)];
    return d;
}

// Writes one texel as the file wrote it into D3D memory: a word in the format's natural packing
// is the little-endian texel; float groups go through the format's float encoding.
void storeTexel(const emu::FormatInfo& f, const Texel& t, uint8_t* p) {
    if (t.count == 0) {
        for (uint32_t b = 0; b < f.bytes; ++b) p[b] = uint8_t(t.bits >> (8 * b));
        return;
    }
    emu::encodeFloat(f, t.value, p);
}

// Fills a locked level from the file's rows (or its fill texel).
void fillLevel(const emu::FormatInfo& f, const TextureLevel& level, uint8_t* bits, size_t rowPitch, size_t slicePitch) {
    for (uint32_t z = 0; z < level.depth; ++z)
        for (uint32_t y = 0; y < level.height; ++y)
            for (uint32_t x = 0; x < level.width; ++x) {
                const Texel& t = level.hasFill
                                     ? level.fill
                                     : level.texels[(size_t(z) * level.height + y) * level.width + x];
                storeTexel(f, t, bits + z * slicePitch + y * rowPitch + size_t(x) * f.bytes);
            }
}

bool setUpTexture(Device& d, const TextureDesc& t, const std::string& path, std::string& error) {
    D3DFORMAT format = emu::d3dFormatOf(t.format.value);
    const emu::FormatInfo* f = emu::formatInfo(format);
    const uint32_t levels = t.levels.value;
    Handle h{};
    if (t.isVolume()) {
        if (levels == 0) {
            error = where(path, t.line) + ": `levels 0` on a volume texture: the device generates mips for 2D "
                                          "textures only (D3DUSAGE_AUTOGENMIPMAP); give the levels";
            return false;
        }
        if (d.CreateVolumeTexture(t.width, t.height, t.depth, levels, 0, format, D3DPOOL_MANAGED, &h) != D3D_OK) {
            error = refused(d, path, t.line, "CreateVolumeTexture");
            return false;
        }
    } else {
        DWORD usage = levels == 0 ? D3DUSAGE_AUTOGENMIPMAP : 0;
        if (d.CreateTexture(t.width, t.height, levels, usage, format, D3DPOOL_MANAGED, &h) != D3D_OK) {
            error = refused(d, path, t.line, "CreateTexture");
            return false;
        }
    }
    for (const TextureLevel& level : t.data) {
        if (t.isVolume()) {
            D3DLOCKED_BOX box;
            if (d.LockBox(h, level.level, &box, nullptr, 0) != D3D_OK) {
                error = refused(d, path, level.line, "LockBox");
                return false;
            }
            fillLevel(*f, level, static_cast<uint8_t*>(box.pBits), size_t(box.RowPitch), size_t(box.SlicePitch));
            d.UnlockBox(h, level.level);
        } else {
            D3DLOCKED_RECT rect;
            if (d.LockRect(h, level.level, &rect, nullptr, 0) != D3D_OK) {
                error = refused(d, path, level.line, "LockRect");
                return false;
            }
            fillLevel(*f, level, static_cast<uint8_t*>(rect.pBits), size_t(rect.Pitch), 0);
            d.UnlockRect(h, level.level);
        }
    }
    if (d.SetTexture(DWORD(t.stage), h) != D3D_OK) {
        error = refused(d, path, t.line, "SetTexture");
        return false;
    }
    return true;
}

bool setUpSampler(Device& d, const SamplerDesc& s, const std::string& path, std::string& error) {
    const DWORD i = DWORD(s.stage);
    const std::pair<D3DSAMPLERSTATETYPE, DWORD> states[] = {
        {D3DSAMP_MINFILTER, DWORD(s.minFilter.value)},   {D3DSAMP_MAGFILTER, DWORD(s.magFilter.value)},
        {D3DSAMP_MIPFILTER, DWORD(s.mipFilter.value)},   {D3DSAMP_ADDRESSU, DWORD(s.addressU.value)},
        {D3DSAMP_ADDRESSV, DWORD(s.addressV.value)},     {D3DSAMP_ADDRESSW, DWORD(s.addressW.value)},
        {D3DSAMP_BORDERCOLOR, argbOf(s.border.value)},
    };
    for (auto [type, value] : states)
        if (d.SetSamplerState(i, type, value) != D3D_OK) {
            error = refused(d, path, s.line, "SetSamplerState");
            return false;
        }
    return true;
}

bool setUpStage(Device& d, const StageDesc& s, const std::string& path, std::string& error) {
    const DWORD i = DWORD(s.stage);
    const std::pair<D3DTEXTURESTAGESTATETYPE, DWORD> states[] = {
        {D3DTSS_COLOROP, DWORD(s.colorOp.value)},
        {D3DTSS_COLORARG0, argValue(s.colorArg0.value)},
        {D3DTSS_COLORARG1, argValue(s.colorArg1.value)},
        {D3DTSS_COLORARG2, argValue(s.colorArg2.value)},
        {D3DTSS_ALPHAOP, DWORD(s.alphaOp.value)},
        {D3DTSS_ALPHAARG0, argValue(s.alphaArg0.value)},
        {D3DTSS_ALPHAARG1, argValue(s.alphaArg1.value)},
        {D3DTSS_ALPHAARG2, argValue(s.alphaArg2.value)},
        {D3DTSS_RESULTARG, argValue(s.resultArg.value)},
        {D3DTSS_BUMPENVMAT00, emu::floatBits(s.bumpEnvMat.value[0])},
        {D3DTSS_BUMPENVMAT01, emu::floatBits(s.bumpEnvMat.value[1])},
        {D3DTSS_BUMPENVMAT10, emu::floatBits(s.bumpEnvMat.value[2])},
        {D3DTSS_BUMPENVMAT11, emu::floatBits(s.bumpEnvMat.value[3])},
        {D3DTSS_BUMPENVLSCALE, emu::floatBits(s.lScale.value)},
        {D3DTSS_BUMPENVLOFFSET, emu::floatBits(s.lOffset.value)},
        {D3DTSS_TEXCOORDINDEX, s.texCoordIndex.value},
        {D3DTSS_TEXTURETRANSFORMFLAGS, s.transformFlags.value.bits},
    };
    for (auto [type, value] : states)
        if (d.SetTextureStageState(i, type, value) != D3D_OK) {
            error = refused(d, path, s.line, "SetTextureStageState");
            return false;
        }
    return true;
}

bool setUpRenderStates(Device& d, const TestFile& file, const std::string& path, std::string& error) {
    const RenderStateDesc& r = file.renderState;
    const bool depth = file.renderTarget.depth.value;
    const std::pair<D3DRENDERSTATETYPE, DWORD> states[] = {
        {D3DRS_ALPHABLENDENABLE, r.alphaBlend.value},
        {D3DRS_SRCBLEND, DWORD(r.srcBlend.value)},
        {D3DRS_DESTBLEND, DWORD(r.destBlend.value)},
        {D3DRS_BLENDOP, DWORD(r.blendOp.value)},
        {D3DRS_BLENDFACTOR, argbOf(r.blendFactor.value)},
        {D3DRS_ALPHATESTENABLE, r.alphaTest.value},
        {D3DRS_ALPHAFUNC, DWORD(r.alphaFunc.value)},
        {D3DRS_ALPHAREF, r.alphaRef.value},
        {D3DRS_TEXTUREFACTOR, argbOf(r.textureFactor.value)},
        {D3DRS_FOGENABLE, r.fog.value},
        {D3DRS_FOGCOLOR, argbOf(r.fogColor.value)},
        {D3DRS_ZENABLE, depth ? DWORD(D3DZB_TRUE) : DWORD(D3DZB_FALSE)},
        {D3DRS_ZFUNC, DWORD(r.zFunc.value)},
        {D3DRS_ZWRITEENABLE, r.zWrite.value},
        {D3DRS_COLORWRITEENABLE, r.colorWrite.value},
        {D3DRS_CULLMODE, DWORD(r.cullMode.value)},
    };
    for (auto [type, value] : states)
        if (d.SetRenderState(type, value) != D3D_OK) {
            error = refused(d, path, r.line, "SetRenderState");
            return false;
        }
    return true;
}

bool setUpTransforms(Device& d, const TestFile& file, const std::string& path, std::string& error) {
    const TransformDesc& t = file.transform;
    auto set = [&](D3DTRANSFORMSTATETYPE type, const Setting<Matrix4>& m) {
        if (!m.isSet()) return true;
        D3DMATRIX matrix = matrixOf(m.value);
        if (d.SetTransform(type, &matrix) == D3D_OK) return true;
        error = refused(d, path, m.line, "SetTransform");
        return false;
    };
    if (!set(D3DTS_WORLD, t.world) || !set(D3DTS_VIEW, t.view) || !set(D3DTS_PROJECTION, t.projection)) return false;
    for (int i = 0; i < ps11::kMaxTextureStages; ++i)
        if (!set(D3DTRANSFORMSTATETYPE(D3DTS_TEXTURE0 + i), t.texture[size_t(i)])) return false;
    if (t.viewport.isSet()) {
        const Viewport& v = t.viewport.value;
        D3DVIEWPORT9 vp;
        vp.X = v.x;
        vp.Y = v.y;
        vp.Width = v.width ? v.width : uint32_t(file.renderTarget.size.value[0]) - v.x;
        vp.Height = v.height ? v.height : uint32_t(file.renderTarget.size.value[1]) - v.y;
        vp.MinZ = v.minZ;
        vp.MaxZ = v.maxZ;
        if (d.SetViewport(&vp) != D3D_OK) {
            error = refused(d, path, t.viewport.line, "SetViewport");
            return false;
        }
    }
    return true;
}

// The vertex layout the runner hands to DrawPrimitiveUP: position (XYZRHW or XYZ), diffuse,
// specular, then `sets` texture coordinate sets of `size[i]` floats.
struct VertexLayout {
    bool pretransformed = true;
    int sets = 0;
    std::array<int, 8> size{};
    DWORD fvf() const {
        DWORD f = (pretransformed ? D3DFVF_XYZRHW : D3DFVF_XYZ) | D3DFVF_DIFFUSE | D3DFVF_SPECULAR;
        f |= DWORD(sets) << D3DFVF_TEXCOUNT_SHIFT;
        for (int i = 0; i < sets; ++i) {
            switch (size[size_t(i)]) {
                case 1: f |= D3DFVF_TEXCOORDSIZE1(DWORD(i)); break;
                case 3: f |= D3DFVF_TEXCOORDSIZE3(DWORD(i)); break;
                case 4: f |= D3DFVF_TEXCOORDSIZE4(DWORD(i)); break;
                default: break;  // 2 is 0
            }
        }
        return f;
    }
    int floats() const {
        int n = (pretransformed ? 4 : 3) + 2;
        for (int i = 0; i < sets; ++i) n += size[size_t(i)];
        return n;
    }
};

// Appends one vertex in the layout's order; colours are stored as their DWORD bits.
void pushVertex(std::vector<uint32_t>& out, const VertexLayout& layout, const Vec4& pos, uint32_t diffuse,
                uint32_t specular, const std::array<Vec4, 8>& tex) {
    auto pushFloat = [&](float v) {
        uint32_t bits;
        std::memcpy(&bits, &v, 4);
        out.push_back(bits);
    };
    for (int c = 0; c < (layout.pretransformed ? 4 : 3); ++c) pushFloat(pos[size_t(c)]);
    out.push_back(diffuse);
    out.push_back(specular);
    for (int i = 0; i < layout.sets; ++i)
        for (int c = 0; c < layout.size[size_t(i)]; ++c) pushFloat(tex[size_t(i)][size_t(c)]);
}

}  // namespace

DrawRunner::~DrawRunner() = default;

std::unique_ptr<DrawRunner> DrawRunner::create(const TestFile& file, const std::string& path, const Program* program,
                                               const HardwareConfig& hardware, std::string& error,
                                               bool fastPaths, const RendererFactory& renderer, bool skipTiles) {
    std::unique_ptr<DrawRunner> r(new DrawRunner());
    r->m_path = path;
    emu::DeviceOptions options;
    options.hardware = hardware.hardware;
    options.precision = hardware.precision;
    options.maxValue = hardware.maxValue;
    options.software.alignedPasses = fastPaths;
    options.software.fastSampler = fastPaths;
    options.software.skipTiles = skipTiles;
    options.renderer = renderer;
    r->m_device = std::make_unique<Device>(options);
    Device& d = *r->m_device;

    const RenderTargetDesc& rt = file.renderTarget;
    r->m_width = rt.size.value[0];
    r->m_height = rt.size.value[1];
    r->m_format = rt.format.value;
    Handle target{};
    if (d.CreateRenderTarget(r->m_width, r->m_height, emu::d3dFormatOf(r->m_format), 0, &target) != D3D_OK ||
        d.SetRenderTarget(0, target) != D3D_OK) {
        error = refused(d, path, rt.line, "CreateRenderTarget");
        return nullptr;
    }
    r->m_target = uint32_t(target);
    DWORD clearFlags = D3DCLEAR_TARGET;
    if (rt.depth.value) {
        Handle depth{};
        if (d.CreateDepthStencilSurface(r->m_width, r->m_height, D3DFMT_D24S8, &depth) != D3D_OK ||
            d.SetDepthStencilSurface(depth) != D3D_OK) {
            error = refused(d, path, rt.line, "CreateDepthStencilSurface");
            return nullptr;
        }
        clearFlags |= D3DCLEAR_ZBUFFER;
    }
    if (d.Clear(0, nullptr, clearFlags, argbOf(rt.clear.value), rt.depthClear, 0) != D3D_OK) {
        error = refused(d, path, rt.line, "Clear");
        return nullptr;
    }
    for (const TextureDesc& t : file.textures)
        if (!setUpTexture(d, t, path, error)) return nullptr;
    for (const SamplerDesc& s : file.samplers)
        if (!setUpSampler(d, s, path, error)) return nullptr;
    for (const StageDesc& s : file.stages)
        if (!setUpStage(d, s, path, error)) return nullptr;
    if (!setUpRenderStates(d, file, path, error) || !setUpTransforms(d, file, path, error)) return nullptr;
    for (const ConstantDesc& c : file.constants)
        if (d.SetPixelShaderConstantF(UINT(c.index), c.value.data(), 1) != D3D_OK) {
            error = refused(d, path, c.line, "SetPixelShaderConstantF");
            return nullptr;
        }
    if (program) {
        std::vector<uint32_t> tokens = encode(*program);
        Handle shader{};
        if (d.CreatePixelShader(std::span<const DWORD>(tokens.data(), tokens.size()), &shader) != D3D_OK ||
            d.SetPixelShader(shader) != D3D_OK) {
            error = refused(d, path, file.pixelShader.line, "CreatePixelShader");
            return nullptr;
        }
    }
    return r;
}

bool DrawRunner::draw(const TestCommand& command, std::string& error) {
    Device& d = *m_device;
    std::vector<uint32_t> data;
    VertexLayout layout;
    D3DPRIMITIVETYPE type = D3DPT_TRIANGLELIST;
    UINT primitives = 0;
    if (const DrawQuad* q = std::get_if<DrawQuad>(&command.op)) {
        layout.sets = 8;
        layout.size.fill(2);
        std::array<uint32_t, 4> rect = q->hasRect ? q->rect : std::array<uint32_t, 4>{0, 0, m_width, m_height};
        // The half-pixel-shifted quad (docs/test-format.md): corners at (x0-0.5, y0-0.5) and
        // (x1-0.5, y1-0.5), so pixel centres get the texture coordinate of their own centre.
        const float x0 = float(rect[0]) - 0.5f, y0 = float(rect[1]) - 0.5f;
        const float x1 = float(rect[2]) - 0.5f, y1 = float(rect[3]) - 0.5f;
        const uint32_t diffuse = argbOf(q->diffuse), specular = argbOf(q->specular);
        auto corner = [&](int cx, int cy) {
            std::array<Vec4, 8> tex{};
            for (size_t i = 0; i < 8; ++i) {
                const Vec4& t = q->texRect[i];
                tex[i] = {cx ? t[2] : t[0], cy ? t[3] : t[1], 0, 1};
            }
            pushVertex(data, layout, {cx ? x1 : x0, cy ? y1 : y0, 0, 1}, diffuse, specular, tex);
        };
        // Two triangles, top-left / top-right / bottom-left and top-right / bottom-right /
        // bottom-left: clockwise on screen, so even D3D9's default CCW culling keeps them.
        corner(0, 0), corner(1, 0), corner(0, 1);
        corner(1, 0), corner(1, 1), corner(0, 1);
        primitives = 2;
    } else {
        const DrawPrimitives& p = std::get<DrawPrimitives>(command.op);
        layout.pretransformed = p.pretransformed;
        for (const Vertex& v : p.vertices)
            for (int i = 0; i < 8; ++i)
                if (v.texComponents[size_t(i)]) {
                    layout.sets = std::max(layout.sets, i + 1);
                    layout.size[size_t(i)] = std::max(layout.size[size_t(i)], int(v.texComponents[size_t(i)]));
                }
        for (int i = 0; i < layout.sets; ++i)
            if (layout.size[size_t(i)] == 0) layout.size[size_t(i)] = 2;  // a gap: zeros
        for (const Vertex& v : p.vertices) pushVertex(data, layout, v.position, v.diffuse, v.specular, v.tex);
        const UINT n = UINT(p.vertices.size());
        switch (p.type) {
            case PrimitiveType::TriangleList:
                type = D3DPT_TRIANGLELIST;
                primitives = n / 3;
                break;
            case PrimitiveType::TriangleStrip:
                type = D3DPT_TRIANGLESTRIP;
                primitives = n - 2;
                break;
            case PrimitiveType::TriangleFan:
                type = D3DPT_TRIANGLEFAN;
                primitives = n - 2;
                break;
        }
    }
    if (d.SetFVF(layout.fvf()) != D3D_OK) {
        error = refused(d, m_path, command.line, "SetFVF");
        return false;
    }
    if (d.DrawPrimitiveUP(type, primitives, data.data(), UINT(layout.floats() * 4)) != D3D_OK) {
        error = refused(d, m_path, command.line, "DrawPrimitiveUP");
        return false;
    }
    m_readBackValid = false;
    const emu::DrawStats& stats = d.lastDrawStats();
    ++m_tally.draws;
    m_tally.pixelsShaded += stats.pixelsShaded;
    m_tally.pixelsWritten += stats.pixelsWritten;
    m_tally.texelsFetched += stats.texelsFetched;
    m_tally.instructions += stats.instructions;
    m_tally.milliseconds += stats.milliseconds;
    m_tally.tilesShaded += stats.tilesShaded;
    m_tally.tilesFilled += stats.tilesFilled;
    m_tally.tilesCopied += stats.tilesCopied;
    m_tally.tilesSkipped += stats.tilesSkipped;
    return true;
}

bool DrawRunner::readBack(std::string& error) {
    if (m_readBackValid) return true;
    Device& d = *m_device;
    const D3DFORMAT format = emu::d3dFormatOf(m_format);
    Handle copy{};
    if (d.CreateOffscreenPlainSurface(m_width, m_height, format, D3DPOOL_SYSTEMMEM, &copy) != D3D_OK ||
        d.GetRenderTargetData(Handle(m_target), copy) != D3D_OK) {
        error = refused(d, m_path, 0, "GetRenderTargetData");
        return false;
    }
    D3DLOCKED_RECT locked;
    if (d.LockRect(copy, &locked, nullptr, D3DLOCK_READONLY) != D3D_OK) {
        error = refused(d, m_path, 0, "LockRect");
        d.Release(copy);
        return false;
    }
    const emu::FormatInfo& f = *emu::formatInfo(format);
    const size_t n = size_t(m_width) * m_height;
    m_pixels.assign(n, Vec4{});
    m_pixelWords.assign(n, 0);
    for (uint32_t y = 0; y < m_height; ++y)
        for (uint32_t x = 0; x < m_width; ++x) {
            const uint8_t* p = static_cast<const uint8_t*>(locked.pBits) + size_t(y) * size_t(locked.Pitch) + x * f.bytes;
            const size_t i = size_t(y) * m_width + x;
            if (f.cls == emu::FormatClass::Unorm8) {
                std::array<uint8_t, 4> b = emu::decodeUnorm8(f, p);
                m_pixelWords[i] = uint32_t(b[3]) << 24 | uint32_t(b[0]) << 16 | uint32_t(b[1]) << 8 | b[2];
                for (int c = 0; c < 4; ++c) m_pixels[i][size_t(c)] = float(b[size_t(c)]);  // levels
            } else {
                m_pixels[i] = emu::decodeTexel(f, p, d.hardware().hardware->signedDecode);
            }
        }
    d.UnlockRect(copy);
    d.Release(copy);
    m_readBackValid = true;
    return true;
}

bool DrawRunner::floatTarget() const { return isFloatFormat(m_format); }

bool DrawRunner::targetPixels(std::vector<Vec4>& out, std::string& error) {
    if (!readBack(error)) return false;
    out = m_pixels;
    return true;
}

std::string DrawRunner::probe(const Probe& probe, std::string& error) {
    if (!readBack(error)) return "";
    std::array<uint32_t, 4> rect = probe.rect;
    if (probe.kind == ProbeKind::All) rect = {0, 0, m_width, m_height};
    const bool bytes = !isFloatFormat(m_format);
    const int n = probe.alpha ? 4 : 3;
    // Expected per channel, in the target's unit (8-bit levels or values).
    std::array<double, 4> expected{};
    for (int c = 0; c < 4; ++c) {
        if (bytes && probe.expected.packed) {
            const int shift = c == 3 ? 24 : 16 - 8 * c;
            expected[size_t(c)] = double((probe.expected.argb >> shift) & 0xff);
        } else {
            expected[size_t(c)] = double(probe.expected.rgba[size_t(c)]) * (bytes ? 255.0 : 1.0);
        }
    }
    size_t failedPixels = 0;
    std::string first;
    for (uint32_t y = rect[1]; y < rect[3] && y < m_height; ++y)
        for (uint32_t x = rect[0]; x < rect[2] && x < m_width; ++x) {
            const size_t i = size_t(y) * m_width + x;
            bool ok = true;
            for (int c = 0; c < n; ++c) {
                const double diff = std::fabs(double(m_pixels[i][size_t(c)]) - expected[size_t(c)]);
                if (!(diff <= double(probe.tolerance))) ok = false;  // NaN never passes
            }
            if (ok) continue;
            if (failedPixels++ == 0) {
                char buf[160];
                if (bytes) {
                    std::snprintf(buf, sizeof buf, "pixel (%u, %u) is 0x%08x", x, y, m_pixelWords[i]);
                } else {
                    const Vec4& v = m_pixels[i];
                    std::snprintf(buf, sizeof buf, "pixel (%u, %u) is %.6g %.6g %.6g %.6g", x, y, double(v[0]),
                                  double(v[1]), double(v[2]), double(v[3]));
                }
                first = buf;
            }
        }
    if (!failedPixels) return "";
    char exp[160];
    if (bytes && probe.expected.packed)
        std::snprintf(exp, sizeof exp, "%s 0x%08x", probe.alpha ? "rgba" : "rgb", probe.expected.argb);
    else
        std::snprintf(exp, sizeof exp, "%s %.6g %.6g %.6g %.6g", probe.alpha ? "rgba" : "rgb",
                      double(probe.expected.rgba[0]), double(probe.expected.rgba[1]), double(probe.expected.rgba[2]),
                      double(probe.expected.rgba[3]));
    char tol[48];
    std::snprintf(tol, sizeof tol, " tol %g", double(probe.tolerance));
    std::string s = std::string("expected ") + exp + tol + ", " + first;
    if (failedPixels > 1) s += " (" + std::to_string(failedPixels) + " pixels differ)";
    return s;
}

}  // namespace ps11test
