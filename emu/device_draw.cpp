// Device front: DrawPrimitiveUP. Validation of the call and of the state the draw reads, the
// pixel program (a shader, or the fixed-function stages lowered by emu/ffp.h), sampler, stage
// and render states resolved into a DrawCall with vertex processing (emu/vertex.h), handed to the
// renderer (emu/renderer.h). docs/device.md "Drawing".
#include <algorithm>
#include <chrono>
#include <cstring>
#include <list>
#include <unordered_map>

#include "emu/device.h"
#include "emu/ffp.h"
#include "emu/output_merger.h"
#include "emu/renderer.h"
#include "emu/vertex.h"
#include "ps11/executor.h"
#include "ps11/texture_sampler.h"

namespace emu {

namespace {

std::string num(uint64_t v) { return std::to_string(v); }

// D3DCAPS9 MaxPrimitiveCount of the era's hardware (0xFFFFF) and a stride limit well above
// any FVF's size (D3DCAPS9 MaxStreamStride was 255–512 on ps 1.x parts).
constexpr uint64_t kMaxPrimitiveCount = 0xFFFFF;
constexpr uint32_t kMaxStride = 2048;
// Lowered fixed-function programs kept per device (cleared when full).
constexpr size_t kMaxLoweredPrograms = 64;

bool drawableFormat(D3DFORMAT f) {
    return f == D3DFMT_A8R8G8B8 || f == D3DFMT_X8R8G8B8 || f == D3DFMT_R32F || f == D3DFMT_A16B16G16R16F ||
           f == D3DFMT_A32B32G32R32F;
}

}  // namespace

uint64_t attributesRead(const ps11::Program& program) {
    uint64_t used = 0;
    auto slot = [&](int i) {
        if (i >= 0 && i < kMaxTexSets) used |= uint64_t(0xF) << attrTex(i, 0);
    };
    for (const ps11::Instruction& ins : program.instructions) {
        if (!ins.info) continue;
        if (ins.info->hasDst && ins.dst.type == ps11::RegType::Texture) slot(ins.dst.index);
        for (int s = 0; s < ins.info->numSrc && s < 3; ++s) {
            const ps11::Src& src = ins.src[size_t(s)];
            if (src.type == ps11::RegType::Input)
                used |= uint64_t(0xF) << (src.index == 0 ? kAttrDiffuse : kAttrSpecular);
            else if (src.type == ps11::RegType::Texture)
                slot(src.index);
        }
    }
    return used;
}

namespace {

bool hasTexkill(const ps11::Program& program) {
    for (const ps11::Instruction& ins : program.instructions)
        if (ins.info && ins.opcode() == ps11::Opcode::TexKill) return true;
    return false;
}

std::optional<ps11::Filter> filterOf(DWORD v, bool mip) {
    switch (v) {
        case D3DTEXF_NONE:
            return ps11::Filter::None;
        case D3DTEXF_POINT:
            return ps11::Filter::Point;
        case D3DTEXF_LINEAR:
            return ps11::Filter::Linear;
        // Anisotropic and the quad filters act as linear (a ps 1.x part's MaxAnisotropy 1).
        case D3DTEXF_ANISOTROPIC:
        case D3DTEXF_PYRAMIDALQUAD:
        case D3DTEXF_GAUSSIANQUAD:
            if (!mip) return ps11::Filter::Linear;
            return std::nullopt;
    }
    return std::nullopt;
}

struct FfpKey {
    std::vector<uint32_t> words;
    bool operator==(const FfpKey&) const = default;
};

// The part of the state the fixed-function lowering reads: stage states, render states and
// which stages have a texture bound.
FfpKey ffpKey(const DeviceState& s) {
    FfpKey k;
    k.words.reserve(kMaxStages * kStageStateLimit + kRenderStateLimit + 1);
    for (const auto& st : s.stageStates) k.words.insert(k.words.end(), st.begin(), st.end());
    k.words.insert(k.words.end(), s.renderStates.begin(), s.renderStates.end());
    uint32_t bound = 0;
    for (size_t i = 0; i < s.textures.size(); ++i)
        if (s.textures[i] != Handle::Null) bound |= 1u << i;
    k.words.push_back(bound);
    return k;
}

size_t hashWords(const std::vector<uint32_t>& w) {
    uint64_t h = 1469598103934665603ull;
    for (uint32_t x : w) h = (h ^ x) * 1099511628211ull;
    return size_t(h);
}

}  // namespace

TransferStats& TransferStats::operator+=(const TransferStats& o) {
    uploads += o.uploads;
    uploadBytes += o.uploadBytes;
    readBacks += o.readBacks;
    readBackBytes += o.readBackBytes;
    return *this;
}

DrawStats& DrawStats::operator+=(const DrawStats& o) {
    draws += o.draws;
    triangles += o.triangles;
    trianglesDrawn += o.trianglesDrawn;
    pixelsCovered += o.pixelsCovered;
    pixelsShaded += o.pixelsShaded;
    pixelsWritten += o.pixelsWritten;
    texelsFetched += o.texelsFetched;
    instructions += o.instructions;
    milliseconds += o.milliseconds;
    return *this;
}

// A lowered fixed-function program, kept while the state the lowering read stays the same.
struct LoweredProgram {
    FfpKey key;
    LoweredStages lowered;
    uint64_t id = 0;  // DrawProgram::key
    uint64_t attrs = 0;
    bool kills = false;
};

// What the front keeps between draws: the lowered fixed-function programs by the state words
// the lowering reads (hash buckets), each with a program identity for the renderer's caches.
struct DrawContext {
    std::unordered_map<size_t, std::list<LoweredProgram>> ffp;
    size_t ffpCount = 0;
    uint64_t nextId = uint64_t(1) << 32;  // above every shader handle
};

HRESULT Device::drawFail(HRESULT hr, const char* code, std::string message) {
    return fail(hr, code, "DrawPrimitiveUP: " + message);
}

HRESULT Device::DrawPrimitiveUP(D3DPRIMITIVETYPE type, UINT primitiveCount, const void* vertexData, UINT stride) {
    const auto t0 = std::chrono::steady_clock::now();
    ok();
    // ---- the call's arguments ----
    switch (type) {
        case D3DPT_TRIANGLELIST:
        case D3DPT_TRIANGLESTRIP:
        case D3DPT_TRIANGLEFAN:
            break;
        case D3DPT_POINTLIST:
        case D3DPT_LINELIST:
        case D3DPT_LINESTRIP:
            return drawFail(D3DERR_NOTAVAILABLE, "E4114",
                            "primitive type " + num(DWORD(type)) + " (points and lines) is not drawn by this device");
        default:
            return drawFail(D3DERR_INVALIDCALL, "E4113",
                            "primitive type " + num(DWORD(type)) + " is not a D3DPRIMITIVETYPE");
    }
    if (primitiveCount == 0 || primitiveCount > kMaxPrimitiveCount)
        return drawFail(D3DERR_INVALIDCALL, "E4115",
                        "primitive count " + num(primitiveCount) + " outside 1.." + num(kMaxPrimitiveCount));
    if (!vertexData) return drawFail(D3DERR_INVALIDCALL, "E4103", "vertex data pointer is null");
    if (m_state.renderTarget == Handle::Null) return drawFail(D3DERR_INVALIDCALL, "E4109", "no render target");
    if (m_state.fvf == 0) return drawFail(D3DERR_INVALIDCALL, "E4117", "no FVF set (SetFVF)");
    std::string why;
    const std::optional<VertexLayout> layout = parseFvf(m_state.fvf, why);
    if (!layout)
        return drawFail(
            D3DERR_INVALIDCALL, "E4117", "FVF 0x" + [&] {
                char b[16];
                std::snprintf(b, sizeof b, "%x", unsigned(m_state.fvf));
                return std::string(b);
            }() + ": " + why);
    if (stride < layout->size || stride > kMaxStride)
        return drawFail(D3DERR_INVALIDCALL, "E4116",
                        "stride " + num(stride) + " outside " + num(layout->size) + ".." + num(kMaxStride) +
                            " (the FVF's vertex is " + num(layout->size) + " bytes)");

    // ---- render target and depth ----
    Resource* rt = nullptr;
    SurfaceRef rtRef;
    Image* target = surfaceImage(m_state.renderTarget, "DrawPrimitiveUP", "render target", &rt, &rtRef);
    if (!target) return m_error.hr;
    if (!drawableFormat(target->format->format))
        return drawFail(D3DERR_INVALIDCALL, "E4118",
                        std::string("render target format ") + target->format->name +
                            " is not drawn (A8R8G8B8, X8R8G8B8, R32F, A16B16G16R16F, A32B32G32R32F)");
    if (rt->locked[rtRef.level]) return drawFail(D3DERR_INVALIDCALL, "E4106", "the render target is locked");
    Resource* ds = nullptr;
    SurfaceRef dsRef;
    Image* depth = nullptr;
    if (m_state.depthStencil != Handle::Null) {
        depth = surfaceImage(m_state.depthStencil, "DrawPrimitiveUP", "depth stencil surface", &ds, &dsRef);
        if (!depth) return m_error.hr;
        if (ds->locked[dsRef.level])
            return drawFail(D3DERR_INVALIDCALL, "E4106", "the depth stencil surface is locked");
        if (depth->width < target->width || depth->height < target->height)
            return drawFail(D3DERR_INVALIDCALL, "E4119",
                            "depth stencil surface " + num(depth->width) + "x" + num(depth->height) +
                                " smaller than the render target " + num(target->width) + "x" + num(target->height));
    }

    // ---- render and stage states the draw reads ----
    const DWORD cull = m_state.renderState(D3DRS_CULLMODE);
    if (cull < D3DCULL_NONE || cull > D3DCULL_CCW)
        return drawFail(D3DERR_INVALIDCALL, "E4119", "D3DRS_CULLMODE " + num(cull) + " is not a D3DCULL value");
    const DWORD shade = m_state.renderState(D3DRS_SHADEMODE);
    if (shade < D3DSHADE_FLAT || shade > D3DSHADE_PHONG)
        return drawFail(D3DERR_INVALIDCALL, "E4119", "D3DRS_SHADEMODE " + num(shade) + " is not a D3DSHADEMODE value");
    const DWORD fill = m_state.renderState(D3DRS_FILLMODE);
    if (fill != 3 /* D3DFILL_SOLID */)
        return drawFail(
            D3DERR_NOTAVAILABLE, "E4120",
            "D3DRS_FILLMODE " + num(fill) + ": only D3DFILL_SOLID (3) is drawn (no point or wireframe fill)");

    // ---- the pixel program ----
    if (!m_draw) m_draw = std::make_shared<DrawContext>();
    DrawContext& dc = *m_draw;
    DrawCall call;
    call.hardware = m_hardware;
    DrawProgram& prog = call.program;
    if (m_state.pixelShader != Handle::Null) {
        const ps11::Program* program = pixelShaderProgram(m_state.pixelShader);
        if (!program)
            return drawFail(D3DERR_INVALIDCALL, "E4102",
                            "pixel shader " + num(uint32_t(m_state.pixelShader)) + " is not a pixel shader");
        prog.program = program;
        prog.key = uint64_t(uint32_t(m_state.pixelShader));  // handles are never reused
        prog.attributesRead = attributesRead(*program);
        prog.kills = hasTexkill(*program);
        for (int s = 0; s < kMaxStages; ++s) {
            ps11::StageState& st = prog.stages[size_t(s)];
            st.bumpMat = {m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT00),
                          m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT01),
                          m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT10),
                          m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT11)};
            st.lumScale = m_state.stageStateFloat(s, D3DTSS_BUMPENVLSCALE);
            st.lumOffset = m_state.stageStateFloat(s, D3DTSS_BUMPENVLOFFSET);
        }
    } else {
        FfpKey key = ffpKey(m_state);
        const size_t h = hashWords(key.words);
        const LoweredProgram* found = nullptr;
        for (const LoweredProgram& entry : dc.ffp[h])
            if (entry.key == key) found = &entry;
        if (!found) {
            CallError error;
            std::optional<LoweredStages> lowered = lowerFixedFunction(m_state, error);
            if (!lowered) return drawFail(error.hr, error.code.c_str(), error.message);
            if (dc.ffpCount >= kMaxLoweredPrograms) {
                dc.ffp.clear();
                dc.ffpCount = 0;
            }
            LoweredProgram entry;
            entry.attrs = attributesRead(lowered->program);
            entry.kills = hasTexkill(lowered->program);
            entry.key = std::move(key);
            entry.lowered = std::move(*lowered);
            entry.id = dc.nextId++;
            auto& bucket = dc.ffp[h];
            bucket.push_back(std::move(entry));
            ++dc.ffpCount;
            found = &bucket.back();
        }
        prog.program = &found->lowered.program;
        prog.key = found->id;
        prog.fixedFunction = true;
        prog.attributesRead = found->attrs;
        prog.kills = found->kills;
        // The lowering places the bump values on the stage texbem samples (emu/ffp.h).
        prog.stages = found->lowered.executorStages;
    }
    for (int i = 0; i < kMaxPsConstants; ++i) prog.constants[size_t(i)] = m_state.psConstants[size_t(i)];

    // ---- textures and sampler states of the stages the program samples ----
    const uint32_t sampled = ps11::sampledStages(*prog.program);
    std::array<std::shared_ptr<const ps11::Texture>, kMaxSamplers>& textures = call.textures;
    std::array<ps11::SamplerState, kMaxSamplers>& samplers = call.samplers;
    for (int s = 0; s < kMaxSamplers; ++s) {
        if (!((sampled >> s) & 1)) continue;
        ps11::SamplerState ss;
        auto filter = [&](D3DSAMPLERSTATETYPE t, bool mip, ps11::Filter& out) -> bool {
            const DWORD v = m_state.samplerState(s, t);
            const std::optional<ps11::Filter> f = filterOf(v, mip);
            if (!f) return false;
            out = *f;
            return true;
        };
        if (!filter(D3DSAMP_MINFILTER, false, ss.minFilter) || !filter(D3DSAMP_MAGFILTER, false, ss.magFilter) ||
            !filter(D3DSAMP_MIPFILTER, true, ss.mipFilter))
            return drawFail(D3DERR_UNSUPPORTEDTEXTUREFILTER, "E4123",
                            "sampler " + num(uint32_t(s)) + ": filter (MIN " +
                                num(m_state.samplerState(s, D3DSAMP_MINFILTER)) + ", MAG " +
                                num(m_state.samplerState(s, D3DSAMP_MAGFILTER)) + ", MIP " +
                                num(m_state.samplerState(s, D3DSAMP_MIPFILTER)) + ") is not a filter the device has");
        const D3DSAMPLERSTATETYPE addr[3] = {D3DSAMP_ADDRESSU, D3DSAMP_ADDRESSV, D3DSAMP_ADDRESSW};
        ps11::TextureAddress* out[3] = {&ss.addressU, &ss.addressV, &ss.addressW};
        for (int a = 0; a < 3; ++a) {
            const DWORD v = m_state.samplerState(s, addr[a]);
            if (v < D3DTADDRESS_WRAP || v > D3DTADDRESS_MIRRORONCE)
                return drawFail(
                    D3DERR_INVALIDCALL, "E4123",
                    "sampler " + num(uint32_t(s)) + ": address mode " + num(v) + " is not a D3DTEXTUREADDRESS");
            *out[a] = ps11::TextureAddress(v);
        }
        const DWORD border = m_state.samplerState(s, D3DSAMP_BORDERCOLOR);
        ss.border = {float((border >> 16) & 0xff) / 255.0f, float((border >> 8) & 0xff) / 255.0f,
                     float(border & 0xff) / 255.0f, float(border >> 24) / 255.0f};
        samplers[size_t(s)] = ss;
        const Handle tex = m_state.textures[size_t(s)];
        if (tex == Handle::Null) continue;  // samples (0, 0, 0, 1)
        // A texture that is also the render target (or holds it) would be read while written.
        if (rt && tex == rtRef.owner && rt->kind != ResourceKind::Surface)
            return drawFail(D3DERR_INVALIDCALL, "E4124",
                            "texture " + num(uint32_t(tex)) + " on stage " + num(uint32_t(s)) +
                                " holds the render target (read and written by one draw)");
        Resource* tr = findResource(tex);
        if (tr) {
            for (size_t l = 0; l < tr->locked.size(); ++l)
                if (tr->locked[l])
                    return drawFail(D3DERR_INVALIDCALL, "E4106",
                                    "texture " + num(uint32_t(tex)) + " on stage " + num(uint32_t(s)) + " is locked");
        }
        if (m_renderer->keepsCopies() && tr) {
            // The renderer takes the texture by identity, and the front's view only if it asks.
            if (tr->autoGenMips() && tr->mipsDirty) regenerateMips(*tr);
            TextureRef& ref = call.textureRefs[size_t(s)];
            ref.resource = uint32_t(tex);
            ref.levels = int(tr->levels.size());
            ref.volume = tr->kind == ResourceKind::VolumeTexture;
            ref.format = tr->format;
            ref.level0 = surfaceDesc(SurfaceRef{tex, 0}, *tr);
            continue;
        }
        textures[size_t(s)] = sampledTexture(tex);
        if (!textures[size_t(s)]) {
            const std::string msg = m_error.message;
            m_error = DeviceError{};
            return drawFail(D3DERR_OUTOFVIDEOMEMORY, "E4111",
                            "texture " + num(uint32_t(tex)) + " on stage " + num(uint32_t(s)) + ": " + msg);
        }
    }
    ok();

    // ---- stage states: texture coordinates and the executor's per-stage values ----
    for (int s = 0; s < kMaxStages; ++s) {
        const DWORD tci = m_state.stageState(s, D3DTSS_TEXCOORDINDEX);
        const bool slotRead = (prog.attributesRead >> attrTex(s, 0)) & 0xF;
        if (slotRead && (tci & 0xFFFF0000u))
            return drawFail(
                D3DERR_INVALIDCALL,
                "E4119", "stage " + num(uint32_t(s)) + ": D3DTSS_TEXCOORDINDEX generation mode 0x" + [&] {
                    char b[16];
                    std::snprintf(b, sizeof b, "%x", unsigned(tci >> 16));
                    return std::string(b);
                }() + " (D3DTSS_TCI_*) is not implemented; only PASSTHRU");
    }
    for (int s = 0; s < kMaxStages; ++s) {
        // D3DTTFF_PROJECTED resolves against the stage's coordinate set in the FVF (any
        // TEXTURETRANSFORMFLAGS value is taken, as D3D9 takes it; ps11::projectionDivisor).
        ps11::StageState& st = prog.stages[size_t(s)];
        const DWORD set = m_state.stageState(s, D3DTSS_TEXCOORDINDEX) & 0xFFFF;
        st.coordComponents = set < DWORD(layout->texCount) ? layout->texSize[size_t(set)] : 4;
        st.textureDimensions = textures[size_t(s)] && textures[size_t(s)]->isVolume() ? 3 : 2;
        if (!prog.fixedFunction) st.transformFlags = m_state.stageState(s, D3DTSS_TEXTURETRANSFORMFLAGS);
    }

    // ---- output merger ----
    if (std::optional<CallError> e = mergeStateError(m_state)) return drawFail(e->hr, e->code.c_str(), e->message);
    call.merge = MergeState::from(m_state, depth != nullptr, m_hardware.precision);
    const MergeState& merge = call.merge;
    DrawStats stats;
    stats.draws = 1;
    stats.triangles = primitiveCount;
    if (merge.writesNothing()) {
        // Nothing can change: skipped without shading (never changes an output pixel).
        stats.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        m_lastDraw = stats;
        m_totalDraw += stats;
        return D3D_OK;
    }
    uint64_t used = prog.attributesRead;
    if (merge.fog) used |= uint64_t(1) << (kAttrSpecular + 3);
    call.usedAttributes = used;
    call.target = MergeTarget{target, depth};
    call.colorSurface = surfaceDesc(rtRef, *rt);
    if (depth) call.depthSurface = surfaceDesc(dsRef, *ds);
    if (m_renderer->keepsCopies())
        call.textureView = [this](int stage) { return sampledTexture(m_state.textures[size_t(stage)]); };
    {
        const D3DVIEWPORT9& vp = m_state.viewport;
        int64_t x0 = vp.X, y0 = vp.Y, x1 = int64_t(vp.X) + vp.Width, y1 = int64_t(vp.Y) + vp.Height;
        if (m_state.renderState(D3DRS_SCISSORTESTENABLE)) {
            const RECT& sc = m_state.scissor;
            x0 = std::max<int64_t>(x0, sc.left);
            y0 = std::max<int64_t>(y0, sc.top);
            x1 = std::min<int64_t>(x1, sc.right);
            y1 = std::min<int64_t>(y1, sc.bottom);
        }
        call.clip.x0 = int(std::clamp<int64_t>(x0, 0, target->width));
        call.clip.y0 = int(std::clamp<int64_t>(y0, 0, target->height));
        call.clip.x1 = int(std::clamp<int64_t>(x1, 0, target->width));
        call.clip.y1 = int(std::clamp<int64_t>(y1, 0, target->height));
    }

    // ---- vertices → screen triangles, pulled by the renderer chunk by chunk ----
    VertexSetup vs;
    vs.layout = &*layout;
    vs.usedAttrs = used;
    call.primitiveCount = primitiveCount;
    call.assemble = [&](uint32_t first, uint32_t count, std::vector<ScreenTriangle>& out) {
        processTriangles(m_state, vs, type, first, count, static_cast<const uint8_t*>(vertexData), stride, out);
    };
    CallError rerr;
    if (!m_renderer->draw(call, stats, rerr)) return drawFail(rerr.hr, rerr.code.c_str(), rerr.message);
    if (stats.trianglesDrawn) {
        rendererWrote(*rt, rtRef.level);
        if (depth && merge.depthWrite) rendererWrote(*ds, dsRef.level);
    }
    stats.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    m_lastDraw = stats;
    m_totalDraw += stats;
    return D3D_OK;
}

}  // namespace emu
