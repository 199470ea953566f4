// Device stage: DrawPrimitiveUP. Validation of the call and of the state the draw reads, then
// vertex processing (emu/vertex.h), triangle setup and rasterisation (emu/raster.h) in bands of
// rows over the worker pool, the executor over 2×2-quad spans (pixel shader or the lowered
// fixed-function stages, emu/ffp.h) with a TextureSampler per worker, and the output merger
// (emu/output_merger.h). docs/device.md "Drawing".
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <list>
#include <unordered_map>

#include "emu/aligned_pass.h"
#include "emu/device.h"
#include "emu/ffp.h"
#include "emu/output_merger.h"
#include "emu/raster.h"
#include "emu/thread_pool.h"
#include "emu/vertex.h"
#include "ps11/diagnostics.h"
#include "ps11/executor.h"
#include "ps11/texture_sampler.h"

namespace emu {

namespace {

std::string num(uint64_t v) { return std::to_string(v); }

// D3DCAPS9 MaxPrimitiveCount of the era's hardware (0xFFFFF) and a stride limit well above
// any FVF's size (D3DCAPS9 MaxStreamStride was 255–512 on ps 1.x parts).
constexpr uint64_t kMaxPrimitiveCount = 0xFFFFF;
constexpr uint32_t kMaxStride = 2048;
// Rows per band handed to a worker: even (quads) and small enough to balance two threads.
constexpr int kBandRows = 16;
// Executors kept per device (cleared when full).
constexpr size_t kMaxCachedExecutors = 64;
// Triangles processed per chunk (vertex processing, setup, rasterisation).
constexpr uint32_t kChunkTriangles = 1024;

bool drawableFormat(D3DFORMAT f) {
    return f == D3DFMT_A8R8G8B8 || f == D3DFMT_X8R8G8B8 || f == D3DFMT_R32F || f == D3DFMT_A16B16G16R16F ||
           f == D3DFMT_A32B32G32R32F;
}

// The attributes a program reads: v0/v1 as diffuse/specular, t# as texture-coordinate slots.
// Conservative: any t# operand (destination of a texture-address instruction in 1_1–1_3, texld/
// texcrd source in 1_4) marks its slot.
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

struct CachedExecutor {
    std::unique_ptr<ps11::Executor> executor;
    uint64_t attrs = 0;  // attributesRead of its program
    bool kills = false;  // the program has texkill
    bool fixedFunction = false;
    std::array<ps11::StageState, kMaxStages> stages{};  // fixed function: LoweredStages::executorStages
};

// Per-device draw machinery: the worker pool and the executors, cached by program identity.
// Executor outputs and the merged live mask of one span.
struct Lanes {
    alignas(32) float color[4][ps11::kMaxSpan];
    alignas(32) int32_t grid[4][ps11::kMaxSpan];
    alignas(32) uint8_t killed[ps11::kMaxSpan];
    alignas(32) uint8_t live[ps11::kMaxSpan];
    alignas(32) float depth[ps11::kMaxSpan];
};

// What a worker keeps between draws (no allocation per draw): its span, lanes and sampler.
struct WorkerScratch {
    QuadSpan span;
    Lanes lanes;
    ps11::TextureSampler sampler;
    AlignedScratch aligned;
};

struct DrawContext {
    explicit DrawContext(int threads) : pool(threads) {
        for (int i = 0; i < pool.size(); ++i) scratch.push_back(std::make_unique<WorkerScratch>());
    }
    ThreadPool pool;
    std::vector<std::unique_ptr<WorkerScratch>> scratch;  // one per worker
    // Pixel shaders: by handle (handles are never reused) and profile.
    std::unordered_map<uint64_t, CachedExecutor> shaders;
    // Fixed function: by the state words the lowering reads.
    std::unordered_map<size_t, std::list<std::pair<FfpKey, CachedExecutor>>> ffp;
    size_t ffpCount = 0;
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
    if (!m_draw) m_draw = std::make_shared<DrawContext>(m_options.threads);
    DrawContext& dc = *m_draw;
    const ps11::ExecutorOptions execOptions = ps11::executorOptionsFor(m_hardware);
    CachedExecutor* exec = nullptr;
    if (m_state.pixelShader != Handle::Null) {
        const ps11::Program* program = pixelShaderProgram(m_state.pixelShader);
        if (!program)
            return drawFail(D3DERR_INVALIDCALL, "E4102",
                            "pixel shader " + num(uint32_t(m_state.pixelShader)) + " is not a pixel shader");
        const uint64_t key = uint64_t(uint32_t(m_state.pixelShader));
        auto it = dc.shaders.find(key);
        if (it == dc.shaders.end()) {
            ps11::Diagnostics diags;
            CachedExecutor ce;
            ce.executor = ps11::Executor::create(*program, execOptions, diags);
            if (!ce.executor)
                return drawFail(D3DERR_INVALIDCALL, "E4121",
                                "the executor refused pixel shader " + num(uint32_t(m_state.pixelShader)));
            ce.attrs = attributesRead(*program);
            ce.kills = hasTexkill(*program);
            if (dc.shaders.size() >= kMaxCachedExecutors) dc.shaders.clear();
            it = dc.shaders.emplace(key, std::move(ce)).first;
        }
        exec = &it->second;
    } else {
        FfpKey key = ffpKey(m_state);
        const size_t h = hashWords(key.words);
        auto& bucket = dc.ffp[h];
        for (auto& entry : bucket)
            if (entry.first == key) exec = &entry.second;
        if (!exec) {
            std::string error;
            std::optional<LoweredStages> lowered = lowerFixedFunction(m_state, error);
            if (!lowered) {
                // The lowering names its own E41xx code first ("E41xx what is wrong").
                std::string code = error.size() >= 5 && error[0] == 'E' ? error.substr(0, 5) : "E4122";
                std::string text = error.size() > 6 && error[0] == 'E' ? error.substr(6) : error;
                m_error.hr = D3DERR_INVALIDCALL;
                m_error.code = code;
                m_error.message = code + " DrawPrimitiveUP: " + text;
                return D3DERR_INVALIDCALL;
            }
            ps11::Diagnostics diags;
            CachedExecutor ce;
            ce.executor = ps11::Executor::create(lowered->program, execOptions, diags);
            if (!ce.executor)
                return drawFail(D3DERR_INVALIDCALL, "E4121", "the executor refused the fixed-function program");
            ce.attrs = attributesRead(lowered->program);
            ce.kills = hasTexkill(lowered->program);
            ce.fixedFunction = true;
            ce.stages = lowered->executorStages;
            if (dc.ffpCount >= kMaxCachedExecutors) {
                dc.ffp.clear();
                dc.ffpCount = 0;
            }
            auto& b = dc.ffp[h];
            b.emplace_back(std::move(key), std::move(ce));
            ++dc.ffpCount;
            exec = &b.back().second;
        }
    }
    ps11::Executor& executor = *exec->executor;

    // ---- textures and sampler states of the stages the program samples ----
    const uint32_t sampled = executor.sampledStages();
    std::array<std::shared_ptr<const ps11::Texture>, kMaxSamplers> textures;
    std::array<ps11::SamplerState, kMaxSamplers> samplers;
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
        const bool slotRead = (exec->attrs >> attrTex(s, 0)) & 0xF;
        if (slotRead && (tci & 0xFFFF0000u))
            return drawFail(
                D3DERR_INVALIDCALL,
                "E4119", "stage " + num(uint32_t(s)) + ": D3DTSS_TEXCOORDINDEX generation mode 0x" + [&] {
                    char b[16];
                    std::snprintf(b, sizeof b, "%x", unsigned(tci >> 16));
                    return std::string(b);
                }() + " (D3DTSS_TCI_*) is not implemented; only PASSTHRU");
    }
    for (int i = 0; i < kMaxPsConstants; ++i) executor.setConstant(i, m_state.psConstants[size_t(i)]);
    for (int s = 0; s < kMaxStages; ++s) {
        // D3DTTFF_PROJECTED resolves against the stage's coordinate set in the FVF (any
        // TEXTURETRANSFORMFLAGS value is taken, as D3D9 takes it; ps11::projectionDivisor).
        const DWORD set = m_state.stageState(s, D3DTSS_TEXCOORDINDEX) & 0xFFFF;
        const uint8_t components = set < DWORD(layout->texCount) ? layout->texSize[size_t(set)] : 4;
        const uint8_t dims = textures[size_t(s)] && textures[size_t(s)]->isVolume() ? 3 : 2;
        if (exec->fixedFunction) {
            // The lowering places the bump values on the stage texbem samples (emu/ffp.h).
            ps11::StageState st = exec->stages[size_t(s)];
            st.coordComponents = components;
            st.textureDimensions = dims;
            executor.setStageState(s, st);
            continue;
        }
        ps11::StageState st;
        st.coordComponents = components;
        st.textureDimensions = dims;
        st.bumpMat = {m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT00), m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT01),
                      m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT10), m_state.stageStateFloat(s, D3DTSS_BUMPENVMAT11)};
        st.lumScale = m_state.stageStateFloat(s, D3DTSS_BUMPENVLSCALE);
        st.lumOffset = m_state.stageStateFloat(s, D3DTSS_BUMPENVLOFFSET);
        st.transformFlags = m_state.stageState(s, D3DTSS_TEXTURETRANSFORMFLAGS);
        executor.setStageState(s, st);
    }

    // ---- output merger ----
    if (std::string e = mergeStateError(m_state, "DrawPrimitiveUP"); !e.empty()) {
        m_error.hr = D3DERR_INVALIDCALL;
        m_error.code = e.substr(0, 5);
        m_error.message = e;
        return D3DERR_INVALIDCALL;
    }
    const MergeState merge = MergeState::from(m_state, depth != nullptr, m_hardware.precision);
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
    const bool shaderDepth = executor.writesDepth();
    const bool kills = exec->kills;
    const bool wantZ = merge.depthTest || (merge.depthWrite && depth);
    uint64_t used = exec->attrs;
    if (merge.fog) used |= uint64_t(1) << (kAttrSpecular + 3);

    // ---- vertices → screen triangles → setups ----
    VertexSetup vs;
    vs.layout = &*layout;
    vs.usedAttrs = used;
    VertexStats vstats;

    ClipRect clip;
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
        clip.x0 = int(std::clamp<int64_t>(x0, 0, target->width));
        clip.y0 = int(std::clamp<int64_t>(y0, 0, target->height));
        clip.x1 = int(std::clamp<int64_t>(x1, 0, target->width));
        clip.y1 = int(std::clamp<int64_t>(y1, 0, target->height));
    }
    // Triangles go through in chunks (memory stays bounded for any count); chunks run one after
    // the other, so primitive order holds across them.
    std::vector<ScreenTriangle> tris;
    std::vector<TriangleSetup> setups;
    bool wrote = false;
    // Screen-aligned passes: rows without quads (emu/aligned_pass.h), decided per triangle.
    MergeTarget mtarget{target, depth};
    AlignedDraw aligned;
    const bool alignedDraw =
        m_options.alignedPasses &&
        prepareAlignedDraw(executor, m_hardware.precision, textures, samplers, merge, mtarget, wantZ, used, aligned);
    std::vector<AlignedTriangle> alignedTris;
    std::vector<uint8_t> isAligned;
    for (uint32_t first = 0; first < primitiveCount; first += kChunkTriangles) {
        const uint32_t chunk = std::min(kChunkTriangles, primitiveCount - first);
        tris.clear();
        setups.clear();
        processTriangles(m_state, vs, type, first, chunk, static_cast<const uint8_t*>(vertexData), stride, tris,
                         &vstats);
        int yLo = clip.y1, yHi = clip.y0;
        for (const ScreenTriangle& t : tris) {
            TriangleSetup s;
            if (!setupTriangle(t, used, clip, s)) continue;
            yLo = std::min(yLo, s.yMin);
            yHi = std::max(yHi, s.yMax);
            setups.push_back(s);
        }
        stats.trianglesDrawn += setups.size();
        isAligned.assign(setups.size(), 0);
        if (alignedDraw && setups.size() <= kMaxAlignedTriangles) {
            alignedTris.resize(setups.size());
            for (size_t i = 0; i < setups.size(); ++i)
                isAligned[i] = prepareAlignedTriangle(aligned, setups[i], alignedTris[i]);
        }

        // ---- rows in bands over the workers ----
        if (!setups.empty()) {
            const int firstBand = (yLo & ~1) / kBandRows;
            const int lastBand = (yHi + kBandRows - 1) / kBandRows;
            const int bands = lastBand - firstBand;
            std::atomic<int> next{0};
            const int workers = std::min(dc.pool.size(), bands);
            std::vector<DrawStats> workerStats(size_t(std::max(workers, 1)));
            const bool fx = ps11::isFixedPoint(m_hardware.precision);
            dc.pool.run(workers, [&](int w) {
                WorkerScratch& ws0 = *dc.scratch[size_t(w)];
                ps11::TextureSampler& sampler = ws0.sampler;
                sampler.setWeightBits(m_hardware.weightBits);
                for (int s = 0; s < kMaxSamplers; ++s) {
                    // Stages the program does not sample are unbound (no texture kept alive).
                    sampler.bind(s, (sampled >> s) & 1 ? textures[size_t(s)] : nullptr);
                    if ((sampled >> s) & 1) sampler.setSamplerState(s, samplers[size_t(s)]);
                }
                const uint64_t fetchedBefore = sampler.texelsFetched();
                QuadSpan* span = &ws0.span;
                Lanes* lanes = &ws0.lanes;
                ps11::PixelInputs in;
                in.quads = true;
                for (int c = 0; c < 4; ++c) {
                    if ((used >> (kAttrDiffuse + c)) & 1) in.color[0][c] = span->attr[kAttrDiffuse + c];
                    if ((used >> (kAttrSpecular + c)) & 1) in.color[1][c] = span->attr[kAttrSpecular + c];
                    for (int t = 0; t < kMaxTexSets; ++t)
                        if ((used >> attrTex(t, c)) & 1) in.texcoord[t][c] = span->attr[attrTex(t, c)];
                }
                ps11::PixelOutputs outp;
                for (int c = 0; c < 4; ++c) {
                    outp.color[c] = lanes->color[c];
                    if (fx) outp.grid[c] = lanes->grid[c];
                }
                outp.killed = lanes->killed;
                outp.depth = shaderDepth ? lanes->depth : nullptr;
                ps11::ExecutorStats es;
                MergeStats ms;
                DrawStats& ws = workerStats[size_t(w)];
                auto emit = [&](QuadSpan& sp) {
                    in.count = sp.count;
                    executor.run(in, sampler, outp, &es);
                    if (kills)
                        for (int L = 0; L < sp.count; ++L)
                            lanes->live[L] = uint8_t(sp.live[L] & (lanes->killed[L] ^ 1));
                    MergeInputs mi;
                    mi.count = sp.count;
                    mi.x = sp.x;
                    mi.y = sp.y;
                    mi.live = kills ? lanes->live : sp.live;
                    for (int c = 0; c < 4; ++c) {
                        mi.color[c] = lanes->color[c];
                        mi.grid[c] = fx ? lanes->grid[c] : nullptr;
                    }
                    mi.fog = merge.fog ? sp.attr[kAttrSpecular + 3] : nullptr;
                    mi.z = shaderDepth ? lanes->depth : (wantZ ? sp.z : nullptr);
                    mergePixels(merge, mi, mtarget, &ms);
                    ws.pixelsCovered += uint64_t(sp.liveCount);
                };
                const std::function<void(QuadSpan&)> emitFn = emit;
                AlignedStats as;
                for (;;) {
                    const int b = next.fetch_add(1, std::memory_order_relaxed);
                    if (b >= bands) break;
                    const int by0 = (firstBand + b) * kBandRows;
                    const int by1 = by0 + kBandRows;
                    // Consecutive aligned triangles go row by row together (emu/aligned_pass.h).
                    const AlignedTriangle* group[kMaxAlignedTriangles];
                    const TriangleSetup* groupSetups[kMaxAlignedTriangles];
                    size_t grouped = 0;
                    auto flush = [&] {
                        if (grouped) drawAlignedRows(aligned, group, groupSetups, grouped, by0, by1, ws0.aligned, as);
                        grouped = 0;
                    };
                    for (size_t i = 0; i < setups.size(); ++i) {
                        const TriangleSetup& s = setups[i];
                        if (s.yMax <= by0 || s.yMin >= by1) continue;
                        if (isAligned[i]) {
                            group[grouped] = &alignedTris[i];
                            groupSetups[grouped++] = &s;
                            continue;
                        }
                        flush();
                        rasterizeRows(s, by0, by1, used, wantZ, *span, emitFn);
                    }
                    flush();
                }
                ws.pixelsCovered += as.pixels;
                ws.pixelsShaded = es.pixels + as.exec.pixels;
                ws.instructions = es.instructions + as.exec.instructions;
                ws.pixelsWritten = ms.written + as.written;
                ws.texelsFetched = sampler.texelsFetched() - fetchedBefore + as.texels;
            });
            for (const DrawStats& ws : workerStats) {
                stats.pixelsCovered += ws.pixelsCovered;
                stats.pixelsShaded += ws.pixelsShaded;
                stats.instructions += ws.instructions;
                stats.pixelsWritten += ws.pixelsWritten;
                stats.texelsFetched += ws.texelsFetched;
            }
            wrote = true;
        }
    }
    if (wrote) {
        markWritten(*rt, rtRef.level);
        if (depth && merge.depthWrite) markWritten(*ds, dsRef.level);
    }
    stats.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    m_lastDraw = stats;
    m_totalDraw += stats;
    return D3D_OK;
}

}  // namespace emu
