// Device front: DrawPrimitiveUP, in stages. Each checks its part of the call and of the state the
// draw reads and resolves it into the DrawCall (emu/renderer.h), or refuses with a CallError
// (emu/call_error.h): the call's arguments, the render target and depth, the raster states, the
// pixel program (a shader, or the fixed-function stages lowered by emu/ffp.h), sampler states and
// textures, stage states, the output merger's states and clip rect, and vertex processing
// (emu/vertex.h) pulled by the renderer. docs/device.md "Drawing".
#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <list>
#include <unordered_map>

#include "emu/device.h"
#include "emu/ffp.h"
#include "emu/output_merger.h"
#include "emu/renderer.h"
#include "emu/tile_facts.h"
#include "emu/vertex.h"
#include "ps11/executor.h"
#include "ps11/texture_sampler.h"

namespace emu {

namespace {

std::string num(uint64_t v) { return std::to_string(v); }

std::string hexText(unsigned v) {
    char b[16];
    std::snprintf(b, sizeof b, "%x", v);
    return std::string(b);
}

CallError refuse(HRESULT hr, const char* code, std::string message) { return CallError{hr, code, std::move(message)}; }

// D3DCAPS9 MaxPrimitiveCount of the era's hardware (0xFFFFF) and a stride limit well above
// any FVF's size (D3DCAPS9 MaxStreamStride was 255–512 on ps 1.x parts).
constexpr uint64_t kMaxPrimitiveCount = 0xFFFFF;
constexpr uint32_t kMaxStride = 2048;
// Lowered fixed-function programs kept per device (cleared when full).
constexpr size_t kMaxLoweredPrograms = 64;

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
    pixelsRowPath += o.pixelsRowPath;
    pixelsShaded += o.pixelsShaded;
    pixelsWritten += o.pixelsWritten;
    texelsFetched += o.texelsFetched;
    instructions += o.instructions;
    tilesShaded += o.tilesShaded;
    tilesFilled += o.tilesFilled;
    tilesCopied += o.tilesCopied;
    tilesSkipped += o.tilesSkipped;
    milliseconds += o.milliseconds;
    return *this;
}

// A lowered fixed-function program, kept while the state the lowering reads
// (DeviceState::FixedFunction) stays the same.
struct LoweredProgram {
    DeviceState state;  // the state it was lowered from; compared over DeviceState::FixedFunction
    LoweredStages lowered;
    uint64_t id = 0;  // DrawProgram::key
    uint64_t attrs = 0;
    bool kills = false;
};

// What the front keeps between draws: the lowered fixed-function programs in buckets by
// DeviceState::hash(FixedFunction), each with a program identity for the renderer's caches.
struct DrawContext {
    std::unordered_map<size_t, std::list<LoweredProgram>> ffp;
    size_t ffpCount = 0;
    uint64_t nextId = uint64_t(1) << 32;  // above every shader handle
};

// One DrawPrimitiveUP call: its arguments, and what the stages resolve, in their order.
struct DrawSetup {
    D3DPRIMITIVETYPE type = D3DPT_TRIANGLELIST;
    UINT primitiveCount = 0;
    const void* vertexData = nullptr;
    UINT stride = 0;
    std::optional<VertexLayout> layout;  // checkCall
    Resource* rt = nullptr;              // resolveTargets: the render target's owner, level, image
    SurfaceRef rtRef;
    Image* target = nullptr;
    Resource* ds = nullptr;  // and the depth stencil surface's (null: none bound)
    SurfaceRef dsRef;
    Image* depth = nullptr;
    VertexSetup vertexSetup;  // vertices
    DrawCall call;            // what goes to the renderer
};

namespace {

// Whether a checked draw certainly writes every pixel of its one-level target, whatever the
// target held (a fingerprint then counts the target's contents as determined): two pretransformed
// triangles that tile an axis-aligned rectangle holding every pixel centre of the viewport, the
// viewport the whole target, neither culled nor clipped (z in [0, 1]); no blending, alpha test,
// depth test, scissor narrower than the target, partial colour write mask, or texkill.
bool writesWholeTarget(const DrawSetup& d, const DeviceState& st, const ps11::Program* program) {
    if (!d.layout || !d.layout->pretransformed || d.primitiveCount != 2 || !d.rt || d.rt->levels.size() != 1) return false;
    const Image& im = *d.target;
    const D3DVIEWPORT9& vp = st.viewport;
    if (vp.X != 0 || vp.Y != 0 || vp.Width != im.width || vp.Height != im.height) return false;
    if (st.renderState(D3DRS_ALPHABLENDENABLE) || st.renderState(D3DRS_ALPHATESTENABLE) ||
        (st.renderState(D3DRS_COLORWRITEENABLE) & 0xF) != 0xF || (d.ds && st.renderState(D3DRS_ZENABLE)))
        return false;
    if (st.renderState(D3DRS_SCISSORTESTENABLE)) {
        const RECT& r = st.scissor;
        if (r.left > 0 || r.top > 0 || r.right < LONG(im.width) || r.bottom < LONG(im.height)) return false;
    }
    if (program)
        for (const ps11::Instruction& in : program->instructions)
            if (in.opcode() == ps11::Opcode::TexKill) return false;
    // The triangles' vertices, in the order the device assembles them (emu/vertex.cpp).
    const size_t count = d.type == D3DPT_TRIANGLELIST ? 6 : 4;
    float v[6][4];
    for (size_t i = 0; i < count; ++i) std::memcpy(v[i], static_cast<const uint8_t*>(d.vertexData) + i * d.stride, 16);
    const int order[3][6] = {{0, 1, 2, 3, 4, 5}, {0, 1, 2, 1, 3, 2}, {1, 2, 0, 2, 3, 0}};  // list, strip, fan
    const int* o = order[d.type == D3DPT_TRIANGLELIST ? 0 : d.type == D3DPT_TRIANGLESTRIP ? 1 : 2];
    float x0 = v[0][0], x1 = v[0][0], y0 = v[0][1], y1 = v[0][1];
    for (size_t i = 0; i < count; ++i) {
        if (!(v[i][2] >= 0.0f && v[i][2] <= 1.0f) || !(v[i][3] > 0.0f)) return false;
        x0 = std::min(x0, v[i][0]), x1 = std::max(x1, v[i][0]), y0 = std::min(y0, v[i][1]), y1 = std::max(y1, v[i][1]);
    }
    // Every pixel centre (integers, 0 .. size − 1) strictly inside the rectangle.
    if (!(x0 < 0.0f && y0 < 0.0f && x1 > float(im.width - 1) && y1 > float(im.height - 1))) return false;
    const DWORD cull = st.renderState(D3DRS_CULLMODE);
    int omitted[2];
    for (int t = 0; t < 2; ++t) {
        // Corners as bits: 1 = (x0, y0), 2 = (x1, y0), 4 = (x1, y1), 8 = (x0, y1).
        int corners = 0;
        double area2 = 0;
        for (int k = 0; k < 3; ++k) {
            const float* a = v[o[3 * t + k]];
            const float* b = v[o[3 * t + (k + 1) % 3]];
            if ((a[0] != x0 && a[0] != x1) || (a[1] != y0 && a[1] != y1)) return false;
            corners |= a[0] == x0 ? (a[1] == y0 ? 1 : 8) : (a[1] == y0 ? 2 : 4);
            area2 += double(a[0]) * double(b[1]) - double(b[0]) * double(a[1]);
        }
        if (std::popcount(unsigned(corners)) != 3 || culledByWinding(cull, area2)) return false;
        omitted[t] = 15 & ~corners;
    }
    // The two halves of one diagonal: the corners they leave out are opposite.
    return (omitted[0] | omitted[1]) == 5 || (omitted[0] | omitted[1]) == 10;
}

}  // namespace

HRESULT Device::drawFail(const CallError& error) {
    return fail(error.hr, error.code.c_str(), "DrawPrimitiveUP: " + error.message);
}

std::optional<CallError> Device::checkCall(DrawSetup& d) const {
    switch (d.type) {
        case D3DPT_TRIANGLELIST:
        case D3DPT_TRIANGLESTRIP:
        case D3DPT_TRIANGLEFAN:
            break;
        case D3DPT_POINTLIST:
        case D3DPT_LINELIST:
        case D3DPT_LINESTRIP:
            return refuse(D3DERR_NOTAVAILABLE, "E4114",
                          "primitive type " + num(DWORD(d.type)) + " (points and lines) is not drawn by this device");
        default:
            return refuse(D3DERR_INVALIDCALL, "E4113",
                          "primitive type " + num(DWORD(d.type)) + " is not a D3DPRIMITIVETYPE");
    }
    if (d.primitiveCount == 0 || d.primitiveCount > kMaxPrimitiveCount)
        return refuse(D3DERR_INVALIDCALL, "E4115",
                      "primitive count " + num(d.primitiveCount) + " outside 1.." + num(kMaxPrimitiveCount));
    if (!d.vertexData) return refuse(D3DERR_INVALIDCALL, "E4103", "vertex data pointer is null");
    // Here, before the FVF: a call with neither reports the missing target (resolveTargets checks
    // the target itself).
    if (m_state.renderTarget == Handle::Null) return refuse(D3DERR_INVALIDCALL, "E4109", "no render target");
    if (m_state.fvf == 0) return refuse(D3DERR_INVALIDCALL, "E4117", "no FVF set (SetFVF)");
    std::string why;
    d.layout = parseFvf(m_state.fvf, why);
    if (!d.layout) return refuse(D3DERR_INVALIDCALL, "E4117", "FVF 0x" + hexText(unsigned(m_state.fvf)) + ": " + why);
    if (d.stride < d.layout->size || d.stride > kMaxStride)
        return refuse(D3DERR_INVALIDCALL, "E4116",
                      "stride " + num(d.stride) + " outside " + num(d.layout->size) + ".." + num(kMaxStride) +
                          " (the FVF's vertex is " + num(d.layout->size) + " bytes)");
    return std::nullopt;
}

std::optional<CallError> Device::resolveTargets(DrawSetup& d) {
    CallError error;
    d.target = findSurface(m_state.renderTarget, "render target", error, &d.rt, &d.rtRef);
    if (!d.target) return error;
    if (!d.target->format->renderTarget)
        return refuse(D3DERR_INVALIDCALL, "E4118",
                      std::string("render target format ") + d.target->format->name + " is not drawn (" +
                          renderTargetFormatList() + ")");
    if (d.rt->locked[d.rtRef.level]) return refuse(D3DERR_INVALIDCALL, "E4106", "the render target is locked");
    if (m_state.depthStencil == Handle::Null) return std::nullopt;
    d.depth = findSurface(m_state.depthStencil, "depth stencil surface", error, &d.ds, &d.dsRef);
    if (!d.depth) return error;
    if (d.ds->locked[d.dsRef.level]) return refuse(D3DERR_INVALIDCALL, "E4106", "the depth stencil surface is locked");
    if (d.depth->width < d.target->width || d.depth->height < d.target->height)
        return refuse(D3DERR_INVALIDCALL, "E4119",
                      "depth stencil surface " + num(d.depth->width) + "x" + num(d.depth->height) +
                          " smaller than the render target " + num(d.target->width) + "x" + num(d.target->height));
    return std::nullopt;
}

std::optional<CallError> Device::checkRasterStates() const {
    const DWORD cull = m_state.renderState(D3DRS_CULLMODE);
    if (cull < D3DCULL_NONE || cull > D3DCULL_CCW)
        return refuse(D3DERR_INVALIDCALL, "E4119", "D3DRS_CULLMODE " + num(cull) + " is not a D3DCULL value");
    const DWORD shade = m_state.renderState(D3DRS_SHADEMODE);
    if (shade < D3DSHADE_FLAT || shade > D3DSHADE_PHONG)
        return refuse(D3DERR_INVALIDCALL, "E4119", "D3DRS_SHADEMODE " + num(shade) + " is not a D3DSHADEMODE value");
    const DWORD fill = m_state.renderState(D3DRS_FILLMODE);
    if (fill != 3 /* D3DFILL_SOLID */)
        return refuse(D3DERR_NOTAVAILABLE, "E4120",
                      "D3DRS_FILLMODE " + num(fill) + ": only D3DFILL_SOLID (3) is drawn (no point or wireframe fill)");
    return std::nullopt;
}

std::optional<CallError> Device::resolveProgram(DrawSetup& d) {
    DrawProgram& prog = d.call.program;
    if (m_state.pixelShader != Handle::Null) {
        const ps11::Program* program = pixelShaderProgram(m_state.pixelShader);
        if (!program)
            return refuse(D3DERR_INVALIDCALL, "E4102",
                          "pixel shader " + num(uint32_t(m_state.pixelShader)) + " is not a pixel shader");
        prog.program = program;
        prog.key = uint64_t(uint32_t(m_state.pixelShader));  // handles are never reused
        prog.attributesRead = attributesRead(*program);
        prog.kills = hasTexkill(*program);
        for (int s = 0; s < kMaxStages; ++s) {
            ps11::StageState& st = prog.stages[size_t(s)];
            st.bumpMat = {
                m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT00), m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT01),
                m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT10), m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT11)};
            st.lumScale = m_state.stageStateFloat(s, D3DTSS_BUMPENVLSCALE);
            st.lumOffset = m_state.stageStateFloat(s, D3DTSS_BUMPENVLOFFSET);
        }
    } else {
        // The lowered program of this fixed-function state, from the cache or lowered now.
        if (!m_draw) m_draw = std::make_shared<DrawContext>();
        DrawContext& dc = *m_draw;
        const size_t h = m_state.hash(DeviceState::FixedFunction);
        const LoweredProgram* found = nullptr;
        if (auto bucket = dc.ffp.find(h); bucket != dc.ffp.end())
            for (const LoweredProgram& entry : bucket->second)
                if (entry.state.equal(m_state, DeviceState::FixedFunction)) {
                    found = &entry;
                    break;
                }
        if (!found) {
            CallError error;
            std::optional<LoweredStages> lowered = lowerFixedFunction(m_state, error);
            if (!lowered) return error;
            if (dc.ffpCount >= kMaxLoweredPrograms) {
                dc.ffp.clear();
                dc.ffpCount = 0;
            }
            LoweredProgram entry;
            entry.attrs = attributesRead(lowered->program);
            entry.kills = hasTexkill(lowered->program);
            entry.state = m_state;
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
    return std::nullopt;
}

// Textures and sampler states of the stages the program samples.
std::optional<CallError> Device::resolveSamplers(DrawSetup& d) {
    DrawCall& call = d.call;
    const uint32_t sampled = ps11::sampledStages(*call.program.program);
    for (int s = 0; s < kMaxSamplers; ++s) {
        if (!((sampled >> s) & 1)) continue;
        ps11::SamplerState ss;
        auto filter = [&](D3DSAMPLERSTATETYPE t, bool mip, ps11::Filter& out) -> bool {
            const std::optional<ps11::Filter> f = filterOf(m_state.samplerState(s, t), mip);
            if (!f) return false;
            out = *f;
            return true;
        };
        if (!filter(D3DSAMP_MINFILTER, false, ss.minFilter) || !filter(D3DSAMP_MAGFILTER, false, ss.magFilter) ||
            !filter(D3DSAMP_MIPFILTER, true, ss.mipFilter))
            return refuse(D3DERR_UNSUPPORTEDTEXTUREFILTER, "E4123",
                          "sampler " + num(uint32_t(s)) + ": filter (MIN " +
                              num(m_state.samplerState(s, D3DSAMP_MINFILTER)) + ", MAG " +
                              num(m_state.samplerState(s, D3DSAMP_MAGFILTER)) + ", MIP " +
                              num(m_state.samplerState(s, D3DSAMP_MIPFILTER)) + ") is not a filter the device has");
        const D3DSAMPLERSTATETYPE addr[3] = {D3DSAMP_ADDRESSU, D3DSAMP_ADDRESSV, D3DSAMP_ADDRESSW};
        ps11::TextureAddress* out[3] = {&ss.addressU, &ss.addressV, &ss.addressW};
        for (int a = 0; a < 3; ++a) {
            const DWORD v = m_state.samplerState(s, addr[a]);
            if (v < D3DTADDRESS_WRAP || v > D3DTADDRESS_MIRRORONCE)
                return refuse(
                    D3DERR_INVALIDCALL, "E4123",
                    "sampler " + num(uint32_t(s)) + ": address mode " + num(v) + " is not a D3DTEXTUREADDRESS");
            *out[a] = ps11::TextureAddress(v);
        }
        const DWORD border = m_state.samplerState(s, D3DSAMP_BORDERCOLOR);
        ss.border = {float((border >> 16) & 0xff) / 255.0f, float((border >> 8) & 0xff) / 255.0f,
                     float(border & 0xff) / 255.0f, float(border >> 24) / 255.0f};
        call.samplers[size_t(s)] = ss;
        const Handle tex = m_state.textures[size_t(s)];
        if (tex == Handle::Null) continue;  // samples (0, 0, 0, 1)
        const std::string where = "texture " + num(uint32_t(tex)) + " on stage " + num(uint32_t(s));
        // A texture that is also the render target (or holds it) would be read while written.
        if (d.rt && tex == d.rtRef.owner && d.rt->kind != ResourceKind::Surface)
            return refuse(D3DERR_INVALIDCALL, "E4124",
                          where + " holds the render target (read and written by one draw)");
        Resource* tr = findResource(tex);
        if (tr) {
            for (size_t l = 0; l < tr->locked.size(); ++l)
                if (tr->locked[l]) return refuse(D3DERR_INVALIDCALL, "E4106", where + " is locked");
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
        CallError error;
        call.textures[size_t(s)] = makeSampled(tex, error);
        if (!call.textures[size_t(s)])
            return refuse(D3DERR_OUTOFVIDEOMEMORY, "E4111", where + ": " + error.code + " " + error.message);
    }
    return std::nullopt;
}

// Texture coordinates and the executor's per-stage values.
std::optional<CallError> Device::resolveStages(DrawSetup& d) const {
    DrawProgram& prog = d.call.program;
    for (int s = 0; s < kMaxStages; ++s) {
        const DWORD tci = m_state.stageState(s, D3DTSS_TEXCOORDINDEX);
        const bool slotRead = (prog.attributesRead >> attrTex(s, 0)) & 0xF;
        if (slotRead && (tci & 0xFFFF0000u))
            return refuse(D3DERR_INVALIDCALL, "E4119",
                          "stage " + num(uint32_t(s)) + ": D3DTSS_TEXCOORDINDEX generation mode 0x" +
                              hexText(unsigned(tci >> 16)) + " (D3DTSS_TCI_*) is not implemented; only PASSTHRU");
    }
    for (int s = 0; s < kMaxStages; ++s) {
        // D3DTTFF_PROJECTED resolves against the stage's coordinate set in the FVF (any
        // TEXTURETRANSFORMFLAGS value is taken, as D3D9 takes it; ps11::projectionDivisor).
        ps11::StageState& st = prog.stages[size_t(s)];
        const DWORD set = m_state.stageState(s, D3DTSS_TEXCOORDINDEX) & 0xFFFF;
        st.coordComponents = set < DWORD(d.layout->texCount) ? d.layout->texSize[size_t(set)] : 4;
        const auto& texture = d.call.textures[size_t(s)];
        st.textureDimensions = texture && texture->isVolume() ? 3 : 2;
        if (!prog.fixedFunction) st.transformFlags = m_state.stageState(s, D3DTSS_TEXTURETRANSFORMFLAGS);
    }
    return std::nullopt;
}

// The output merger's states, and the clip rect: viewport ∩ scissor (when enabled) ∩ target.
std::optional<CallError> Device::resolveMerge(DrawSetup& d) const {
    if (std::optional<CallError> error = mergeStateError(m_state)) return error;
    DrawCall& call = d.call;
    call.merge = MergeState::from(m_state, d.depth != nullptr, m_hardware.precision);
    const D3DVIEWPORT9& vp = m_state.viewport;
    int64_t x0 = vp.X, y0 = vp.Y, x1 = int64_t(vp.X) + vp.Width, y1 = int64_t(vp.Y) + vp.Height;
    if (m_state.renderState(D3DRS_SCISSORTESTENABLE)) {
        const RECT& sc = m_state.scissor;
        x0 = std::max<int64_t>(x0, sc.left);
        y0 = std::max<int64_t>(y0, sc.top);
        x1 = std::min<int64_t>(x1, sc.right);
        y1 = std::min<int64_t>(y1, sc.bottom);
    }
    call.clip.x0 = int(std::clamp<int64_t>(x0, 0, d.target->width));
    call.clip.y0 = int(std::clamp<int64_t>(y0, 0, d.target->height));
    call.clip.x1 = int(std::clamp<int64_t>(x1, 0, d.target->width));
    call.clip.y1 = int(std::clamp<int64_t>(y1, 0, d.target->height));
    return std::nullopt;
}

// Vertices → screen triangles, pulled by the renderer chunk by chunk: only the attributes the
// program reads (and the specular alpha for fog) are carried.
void Device::vertices(DrawSetup& d) {
    DrawCall& call = d.call;
    uint64_t used = call.program.attributesRead;
    if (call.merge.fog) used |= uint64_t(1) << (kAttrSpecular + 3);
    call.usedAttributes = used;
    d.vertexSetup.layout = &*d.layout;
    d.vertexSetup.usedAttrs = used;
    call.primitiveCount = d.primitiveCount;
    call.assemble = [this, &d](uint32_t first, uint32_t count, std::vector<ScreenTriangle>& out) {
        processTriangles(m_state, d.vertexSetup, d.type, first, count, static_cast<const uint8_t*>(d.vertexData),
                         d.stride, out);
    };
}

// The surfaces by identity, and the call to the renderer; the levels it drew into are marked.
std::optional<CallError> Device::submit(DrawSetup& d, DrawStats& stats) {
    DrawCall& call = d.call;
    call.target = MergeTarget{d.target, d.depth};
    call.colorSurface = surfaceDesc(d.rtRef, *d.rt);
    if (d.depth) call.depthSurface = surfaceDesc(d.dsRef, *d.ds);
    if (m_renderer->keepsCopies())
        call.textureView = [this](int stage) { return sampledTexture(m_state.textures[size_t(stage)]); };
    prepareWrite(*d.rt);
    if (d.depth) prepareWrite(*d.ds);
    // A target of known tile facts keeps them, with the tiles the triangles reach marked stale.
    std::shared_ptr<const std::vector<uint8_t>> uniform = d.rtRef.level == 0 ? d.rt->uniformStale : nullptr;
    CallError error;
    // (The boxes of the triangles the renderer assembles are kept for markDrawnTiles.)
    std::optional<AssembledBoxes> assembled;
    if (uniform) assembled.emplace(call);
    if (!m_renderer->draw(call, stats, error)) return error;
    if (stats.trianglesDrawn) {
        rendererWrote(*d.rt, d.rtRef.level, /*setsPad=*/true);  // every path stores X8's X byte as 1s
        if (d.depth && call.merge.depthWrite) rendererWrote(*d.ds, d.dsRef.level);
        if (uniform) d.rt->uniformStale = markDrawnTiles(call, *d.target, *uniform, &*assembled);
    }
    return std::nullopt;
}

HRESULT Device::DrawPrimitiveUP(D3DPRIMITIVETYPE type, UINT primitiveCount, const void* vertexData, UINT stride) {
    const auto t0 = std::chrono::steady_clock::now();
    ok();
    DrawSetup d;
    d.type = type;
    d.primitiveCount = primitiveCount;
    d.vertexData = vertexData;
    d.stride = stride;
    d.call.hardware = m_hardware;
    if (std::optional<CallError> e = checkCall(d)) return drawFail(*e);
    if (std::optional<CallError> e = resolveTargets(d)) return drawFail(*e);
    if (m_fingerprint.active) {
        // The call, its vertices and the whole state; the textures it may sample, the depth
        // surface it tests against and the target it blends onto, by contents.
        const uint64_t vertexCount = type == D3DPT_TRIANGLELIST ? 3ull * primitiveCount : uint64_t(primitiveCount) + 2;
        const uint32_t words[] = {0x44524157u, uint32_t(type), primitiveCount, stride};  // "DRAW"
        fingerprintWords(words, sizeof words);
        fingerprintWords(vertexData, size_t(vertexCount) * stride);
        // The whole state, written in place (the count folds to a constant).
        std::vector<uint32_t>& print = m_fingerprint.print.words;
        const size_t at = print.size();
        print.resize(at + m_state.wordCount());
        uint32_t* out = print.data() + at;
        m_state.forEachWord([&out](uint32_t w) { *out++ = w; });
        for (Handle t : m_state.textures) fingerprintRead(ownerOf(t));
        const bool depthTest = d.ds && m_state.renderStates[D3DRS_ZENABLE];
        if (depthTest) fingerprintRead(d.dsRef.owner);
        if (m_state.renderStates[D3DRS_ALPHABLENDENABLE]) fingerprintRead(d.rtRef.owner);
        const ps11::Program* program = m_state.pixelShader != Handle::Null ? pixelShaderProgram(m_state.pixelShader) : nullptr;
        fingerprintWrite(d.rtRef.owner, writesWholeTarget(d, m_state, program));
        if (depthTest && m_state.renderStates[D3DRS_ZWRITEENABLE]) fingerprintWrite(d.dsRef.owner, false);
        return D3D_OK;
    }
    if (std::optional<CallError> e = checkRasterStates()) return drawFail(*e);
    if (std::optional<CallError> e = resolveProgram(d)) return drawFail(*e);
    if (std::optional<CallError> e = resolveSamplers(d)) return drawFail(*e);
    if (std::optional<CallError> e = resolveStages(d)) return drawFail(*e);
    if (std::optional<CallError> e = resolveMerge(d)) return drawFail(*e);

    DrawStats stats;
    stats.draws = 1;
    stats.triangles = primitiveCount;
    // A merge state that writes nothing is skipped without shading (never changes an output pixel).
    if (!d.call.merge.writesNothing()) {
        vertices(d);
        if (std::optional<CallError> e = submit(d, stats)) return drawFail(*e);
    }
    stats.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    m_lastDraw = stats;
    m_totalDraw += stats;
    return D3D_OK;
}

}  // namespace emu
