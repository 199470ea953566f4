// `ps11 debug --technique` (glare/frame_debug.h): two runs of a frame with every pass's inputs and
// outputs captured, the walk back from one output pixel, and the retrace of each shader pass
// visited on both profiles.
#include "glare/frame_debug.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <tuple>

#include "emu/blit.h"
#include "emu/format.h"
#include "emu/fullscreen.h"
#include "emu/output_merger.h"
#include "emu/raster.h"
#include "emu/vertex.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "ps11/assembler.h"
#include "ps11/executor.h"
#include "ps11/texture_sampler.h"
#include "ps11/validator.h"

namespace glare {
namespace {

// One texture's level 0 as a pass saw it (before it ran) or left it (after), rows packed.
struct Capture {
    D3DFORMAT format = D3DFMT_UNKNOWN;
    uint32_t width = 0, height = 0, bytesPerPixel = 4;
    std::vector<uint8_t> bytes;
    mutable std::shared_ptr<const ps11::Texture> sampled;

    // The texel as a sampler reads it: 8-bit formats n/255, float formats their floats.
    std::array<float, 4> pixel(uint32_t x, uint32_t y) const {
        const uint8_t* p = &bytes[(size_t(y) * width + x) * bytesPerPixel];
        const emu::FormatInfo& f = *emu::formatInfo(format);
        if (f.cls == emu::FormatClass::Unorm8) {
            const std::array<uint8_t, 4> b = emu::decodeUnorm8(f, p);
            return {b[0] / 255.0f, b[1] / 255.0f, b[2] / 255.0f, b[3] / 255.0f};
        }
        return emu::decodeTexel(f, p, ps11::SignedDecode{});
    }
    const uint8_t* at(uint32_t x, uint32_t y) const { return &bytes[(size_t(y) * width + x) * bytesPerPixel]; }
    std::shared_ptr<const ps11::Texture> texture(std::string& error) const {
        if (sampled) return sampled;
        ps11::TextureLevelBytes level{width, height, 1, bytes.data(), size_t(width) * bytesPerPixel,
                                      size_t(width) * bytesPerPixel * height};
        std::optional<ps11::Texture> t =
            ps11::Texture::fromLevels(emu::formatInfo(format)->texFormat, false, &level, 1, ps11::SignedDecode{}, error);
        if (t) sampled = std::make_shared<const ps11::Texture>(std::move(*t));
        return sampled;
    }
};

struct PassCapture {
    std::map<uint32_t, Capture> before, after;  // by texture index: what it read, what it wrote
};

// One profile's run of the frames, the last one captured.
struct FrameRun {
    std::unique_ptr<Runner> runner;
    std::vector<PassGraph::PassNode> passes;
    std::vector<PassGraph::TextureNode> textures;
    std::vector<PassCapture> captures;  // by pass index
    std::array<std::array<float, 4>, 8> constants{};  // c0..c7 as the passes found them
    bool constantsTaken = false;
    ps11::HardwareConfig hw;
};

bool capture(Runner& runner, emu::Handle texture, Capture& out, std::string& error) {
    return runner.readPixels(
        texture,
        [&](const Runner::Pixels& p) {
            out.format = p.format;
            out.width = p.width, out.height = p.height;
            out.bytesPerPixel = emu::formatInfo(p.format)->bytes;
            const size_t row = size_t(p.width) * out.bytesPerPixel;
            out.bytes.resize(row * p.height);
            for (uint32_t y = 0; y < p.height; ++y) std::memcpy(&out.bytes[y * row], p.data + y * p.pitch, row);
            return true;
        },
        error);
}

bool runFrames(const FrameDebugRequest& rq, uint32_t width, uint32_t height, FrameRun& cls, FrameRun& ideal,
               std::string& error) {
    RunnerOptions ro;
    ro.width = width, ro.height = height;
    ro.device.hardware = rq.hardware;
    ro.skip = false;  // every pass runs, every tile drawn: what the captures show is what ran
    cls.runner = std::make_unique<Runner>(ro);
    ro.device.precision = ps11::Precision::Ideal;
    ideal.runner = std::make_unique<Runner>(ro);
    cls.hw = cls.runner->device().hardware();
    ideal.hw = ideal.runner->device().hardware();
    std::unique_ptr<Scene> scene;
    if (rq.image) {
        if (!cls.runner->setImage(*rq.image, error) || !ideal.runner->setImage(*rq.image, error)) return false;
    } else {
        scene = makeScene(rq.scene, error);
        if (!scene) return false;
        const auto [fogStart, fogEnd] = rq.technique->sceneGlowFog(rq.settings);
        scene->setGlowFog(fogStart, fogEnd);
    }
    const int frames = rq.frame + 1;
    for (int f = 0; f < frames; ++f) {
        if (scene) {
            // The scene drawn on the class, and handed to ideal as it came out (as `ps11 glare
            // --compare` does): both follow the same input.
            double ms = 0;
            if (!cls.runner->renderScene(*scene, f, frames, ms, error)) return false;
            std::optional<emu::RgbaImage> input = cls.runner->readTexture(cls.runner->sceneTexture(), error);
            if (!input || !ideal.runner->setImage(*input, error)) return false;
        }
        for (FrameRun* run : {&cls, &ideal}) {
            const bool last = f == frames - 1;
            const PassGraph* graph = nullptr;
            PassGraph::Hook hook;
            if (last)
                hook = [&, run](uint32_t pass, bool after, std::string& e) {
                    emu::Device& d = run->runner->device();
                    if (!run->constantsTaken) {
                        // The first hook comes before any pass: the state every pass starts from.
                        for (size_t c = 0; c < 8; ++c) run->constants[c] = d.state().psConstants[c];
                        run->constantsTaken = true;
                        run->captures.resize(graph->passes().size());
                    }
                    const PassGraph::PassNode& n = graph->passes()[pass];
                    for (TextureId id : after ? n.writes : n.reads) {
                        const PassGraph::TextureNode& t = graph->texture(id);
                        if (t.data || t.device == emu::Handle::Null) continue;
                        PassCapture& pc = run->captures[pass];
                        if (!capture(*run->runner, t.device, (after ? pc.after : pc.before)[id.index], e)) return false;
                    }
                    return true;
                };
            FrameResult result;
            const bool ok = run->runner->runFrame(
                *rq.technique, rq.settings, f, frames, result, error, hook,
                [&, run](PassGraph& g) {
                    graph = &g;
                    run->passes = g.passes();
                    run->textures = g.textures();
                },
                true);
            if (!ok) {
                if (run == &ideal) error = "ideal: " + error;
                return false;
            }
        }
    }
    return true;
}

// The attributes the rasteriser gives pixel (x, y) of a w×h target for the half-pixel quad
// (emu/fullscreen.h) with `coords`: the same vertices, vertex processing, triangle setup and
// plane evaluation as the draw.
bool quadAttributes(uint32_t w, uint32_t h, const std::array<emu::QuadCoords, 4>& coords, int x, int y,
                    std::array<float, emu::kAttrCount>& attr) {
    const std::array<emu::QuadVertex, 4> verts = emu::halfPixelQuad(0, 0, float(w), float(h), coords);
    emu::DeviceState st;
    st.renderStates[D3DRS_CULLMODE] = D3DCULL_NONE;
    std::string err;
    const std::optional<emu::VertexLayout> layout = emu::parseFvf(emu::kQuadFvf, err);
    if (!layout) return false;
    emu::VertexSetup vs;
    vs.layout = &*layout;
    std::vector<emu::ScreenTriangle> tris;
    emu::processTriangles(st, vs, D3DPT_TRIANGLESTRIP, 0, 2, reinterpret_cast<const uint8_t*>(verts.data()),
                          sizeof(emu::QuadVertex), tris);
    const emu::ClipRect clip{0, 0, int(w), int(h)};
    for (const emu::ScreenTriangle& t : tris) {
        emu::TriangleSetup s;
        int xl = 0, xr = 0;
        if (!emu::setupTriangle(t, ~uint64_t(0), clip, s) || s.perspective) continue;
        if (!emu::rowCoverage(s, y, xl, xr) || x < xl || x >= xr) continue;
        for (int k = 0; k < emu::kAttrCount; ++k)
            attr[size_t(k)] = ((s.constMask >> k) & 1) ? s.constValue[size_t(k)]
                                                       : emu::planeValue(s.attr[size_t(k)], s.ox, s.oy, x, y);
        return true;
    }
    return false;
}

// The texels a clamp-addressed lookup at (u, v) reads, largest weight first (fx: 8-bit weights).
std::vector<DebugTexel> tapTexels(float u, float v, uint32_t w, uint32_t h, bool linear, bool fx) {
    auto clampi = [](int64_t i, uint32_t n) { return uint32_t(std::clamp<int64_t>(i, 0, int64_t(n) - 1)); };
    if (!linear) return {{clampi(int64_t(std::floor(double(u) * w)), w), clampi(int64_t(std::floor(double(v) * h)), h), 1}};
    const double px = double(u) * w - 0.5, py = double(v) * h - 0.5;
    const double x0 = std::floor(px), y0 = std::floor(py);
    double fx1 = px - x0, fy1 = py - y0;
    if (fx) fx1 = std::nearbyint(fx1 * 256) / 256, fy1 = std::nearbyint(fy1 * 256) / 256;
    std::vector<DebugTexel> t;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const double wgt = (i ? fx1 : 1 - fx1) * (j ? fy1 : 1 - fy1);
            if (wgt <= 0) continue;
            const uint32_t tx = clampi(int64_t(x0) + i, w), ty = clampi(int64_t(y0) + j, h);
            auto same = std::find_if(t.begin(), t.end(), [&](const DebugTexel& d) { return d.x == tx && d.y == ty; });
            if (same != t.end())
                same->weight += wgt;
            else
                t.push_back({tx, ty, wgt});
        }
    std::stable_sort(t.begin(), t.end(), [](const DebugTexel& a, const DebugTexel& b) { return a.weight > b.weight; });
    return t;
}

double levelsBetween(const std::array<float, 4>& a, const std::array<float, 4>& b) {
    double m = 0;
    for (size_t c = 0; c < 4; ++c) m = std::max(m, std::fabs(double(a[c]) - double(b[c])) * 255.0);
    return m;
}

struct Traced {
    std::vector<ps11::TraceStep> steps;
    std::array<float, 4> r0{}, stored{};
    std::array<int32_t, 4> grid{};
    uint8_t killed = 0;
    ps11::TextureSampler sampler;
};

// Retraces pass `p` of `run` at (x, y): its program on the run's profile, its stages bound to the
// textures as it read them, its constants; then r0 through its blend and store.
bool tracePass(const FrameRun& run, const ps11::Program& program, uint32_t p, uint32_t target, int x, int y,
               const std::array<float, emu::kAttrCount>& attr, Traced& out, std::string& error) {
    const PassGraph::PassNode& node = run.passes[p];
    const PassCapture& pc = run.captures[p];
    ps11::ExecutorOptions opt = ps11::executorOptionsFor(run.hw);
    opt.path = ps11::ExecPath::Generic;
    ps11::Diagnostics diags;
    std::unique_ptr<ps11::Executor> ex = ps11::Executor::create(program, opt, diags);
    if (!ex) {
        error = "pass " + node.info.name + ": the executor refuses " + node.info.shader;
        return false;
    }
    for (int c = 0; c < 8; ++c) ex->setConstant(c, run.constants[size_t(c)]);
    for (const auto& [reg, value] : node.info.constants) ex->setConstant(reg, value);
    out.sampler.setWeightBits(run.hw.weightBits);
    for (size_t s = 0; s < node.info.stages.size(); ++s) {
        const PassStage& st = node.info.stages[s];
        auto it = pc.before.find(st.texture.index);
        if (it == pc.before.end()) {
            error = "pass " + node.info.name + ": stage " + std::to_string(s) + "'s texture was not captured";
            return false;
        }
        std::shared_ptr<const ps11::Texture> tex = it->second.texture(error);
        if (!tex) return false;
        out.sampler.bind(int(s), tex);
        ps11::SamplerState ss;
        ss.minFilter = ss.magFilter = st.filter == D3DTEXF_POINT ? ps11::Filter::Point : ps11::Filter::Linear;
        ss.mipFilter = ps11::Filter::None;
        ss.addressU = ss.addressV = ss.addressW = ps11::TextureAddress::Clamp;
        out.sampler.setSamplerState(int(s), ss);
    }
    float in[emu::kAttrCount];
    for (int k = 0; k < emu::kAttrCount; ++k) in[k] = attr[size_t(k)];
    ps11::PixelInputs pi;
    pi.count = 1;
    for (int c = 0; c < 4; ++c) {
        pi.color[0][c] = &in[emu::kAttrDiffuse + c];
        pi.color[1][c] = &in[emu::kAttrSpecular + c];
        for (int t = 0; t < ps11::kMaxTexCoordSets; ++t) pi.texcoord[t][c] = &in[emu::attrTex(t, c)];
    }
    ps11::PixelOutputs po;
    const bool fx = ps11::isFixedPoint(run.hw.precision);
    for (int c = 0; c < 4; ++c) {
        po.color[c] = &out.r0[size_t(c)];
        if (fx) po.grid[c] = &out.grid[size_t(c)];
    }
    po.killed = &out.killed;
    ex->trace(pi, out.sampler, po, out.steps);

    // The store: the pass's blend onto what the target held, into one texel of its format.
    const Capture& written = pc.after.at(target);
    emu::DeviceState st;
    if (node.info.blend != Blend::None) {
        st.renderStates[D3DRS_ALPHABLENDENABLE] = 1;
        st.renderStates[D3DRS_SRCBLEND] = node.info.blend == Blend::Add ? D3DBLEND_ONE : D3DBLEND_SRCALPHA;
        st.renderStates[D3DRS_DESTBLEND] = node.info.blend == Blend::Add ? D3DBLEND_ONE : D3DBLEND_INVSRCALPHA;
        st.renderStates[D3DRS_BLENDOP] = D3DBLENDOP_ADD;
    }
    const emu::MergeState ms = emu::MergeState::from(st, false, run.hw.precision);
    emu::Image img;
    img.format = emu::formatInfo(written.format);
    img.width = img.height = 1;
    img.rowPitch = img.format->bytes;
    img.slicePitch = img.format->bytes;
    img.bytes.assign(img.format->bytes, 0);
    auto before = pc.before.find(target);
    if (before != pc.before.end()) std::memcpy(img.bytes.data(), before->second.at(uint32_t(x), uint32_t(y)), img.format->bytes);
    if (!out.killed) {
        const int32_t zero = 0;
        emu::MergeInputs mi;
        mi.count = 1;
        mi.x = mi.y = &zero;
        for (int c = 0; c < 4; ++c) {
            mi.color[c] = &out.r0[size_t(c)];
            if (fx) mi.grid[c] = &out.grid[size_t(c)];
        }
        emu::mergePixels(ms, mi, emu::MergeTarget{&img, nullptr}, nullptr);
    }
    Capture one;
    one.format = written.format;
    one.width = one.height = 1;
    one.bytesPerPixel = img.format->bytes;
    one.bytes.assign(img.bytes.begin(), img.bytes.end());
    out.stored = one.pixel(0, 0);
    return true;
}

class Walk {
public:
    Walk(const FrameDebugRequest& rq, FrameRun& cls, FrameRun& ideal, FrameDebug& out)
        : m_rq(rq), m_cls(cls), m_ideal(ideal), m_out(out) {}

    // Visits pass p at (x, y); its index in m_out.passes (−1 on failure, `m_error` set).
    int visit(uint32_t p, uint32_t x, uint32_t y) {
        if (auto it = m_seen.find(p); it != m_seen.end()) return it->second;
        const PassGraph::PassNode& node = m_cls.passes[p];
        DebugPass dp;
        dp.pass = node.info.name;
        dp.kind = passKindName(node.info.kind);
        dp.shader = node.info.shader;
        dp.note = node.info.note;
        dp.graphIndex = int(p);
        dp.x = x, dp.y = y;
        int target = -1;
        for (TextureId id : node.writes)
            if (!m_cls.textures[id.index].data) {
                target = int(id.index);
                break;
            }
        const int index = int(m_out.passes.size());
        m_seen[p] = index;
        m_out.passes.push_back(dp);
        if (target >= 0) {
            const PassGraph::TextureNode& t = m_cls.textures[size_t(target)];
            dp.target = t.name;
            dp.width = t.desc.width, dp.height = t.desc.height;
            const Capture& a = m_cls.captures[p].after.at(uint32_t(target));
            const Capture& b = m_ideal.captures[p].after.at(uint32_t(target));
            dp.emulated = a.pixel(x, y);
            dp.ideal = b.pixel(x, y);
            dp.levels = levelsBetween(dp.emulated, dp.ideal);
        }
        if (target >= 0 && node.info.kind == PassKind::Shader && !shaderPass(p, uint32_t(target), dp)) return -1;
        if (target >= 0 && node.info.kind == PassKind::StretchRect && !stretchPass(p, uint32_t(target), dp)) return -1;
        double in = 0;
        for (const DebugSource& s : dp.sources) in = std::max(in, s.levels);
        dp.added = dp.levels - in;
        m_out.passes[size_t(index)] = std::move(dp);
        return index;
    }

    std::string m_error;

private:
    // The last live pass before `p` that wrote texture t, or −1.
    int writerBefore(uint32_t p, uint32_t t) const {
        for (int j = int(p) - 1; j >= 0; --j) {
            const PassGraph::PassNode& n = m_cls.passes[size_t(j)];
            if (!n.live) continue;
            for (TextureId id : n.writes)
                if (id.index == t) return j;
        }
        return -1;
    }

    // s.levels: the largest difference among the texels it reads, as pass p read them.
    void measure(uint32_t p, uint32_t t, DebugSource& s) const {
        const Capture& a = m_cls.captures[p].before.at(t);
        const Capture& b = m_ideal.captures[p].before.at(t);
        for (const DebugTexel& tx : s.texels) s.levels = std::max(s.levels, levelsBetween(a.pixel(tx.x, tx.y), b.pixel(tx.x, tx.y)));
    }

    // s.from / s.origin: the pass that wrote texture t before pass p, visited at the first
    // (largest-weight) texel.
    bool follow(uint32_t p, uint32_t t, DebugSource& s) {
        const int w = writerBefore(p, t);
        if (w < 0) {
            const PassGraph::TextureNode& n = m_cls.textures[t];
            s.origin = n.name == "scene" ? (m_rq.image ? "input image" : "scene input")
                                         : n.imported ? "kept from the previous frame" : "not written this frame";
            return true;
        }
        s.origin = m_cls.passes[size_t(w)].info.name;
        if (s.texels.empty()) return true;
        const int from = visit(uint32_t(w), s.texels[0].x, s.texels[0].y);
        if (from < 0) return false;
        s.from = from;
        return true;
    }

    const ps11::Program* program(const std::string& file) {
        if (auto it = m_programs.find(file); it != m_programs.end()) return &it->second;
        const std::string_view* text = shaderText(file);
        if (!text) {
            m_error = "no shader glare/shaders/" + file;
            return nullptr;
        }
        ps11::Diagnostics diags;
        std::optional<ps11::Program> p = ps11::parseAssembly(*text, "glare/shaders/" + file, {}, diags);
        if (!p || !ps11::validate(*p, diags)) {
            m_error = "glare/shaders/" + file + " does not assemble";
            return nullptr;
        }
        return &m_programs.emplace(file, std::move(*p)).first->second;
    }

    bool shaderPass(uint32_t p, uint32_t target, DebugPass& dp) {
        const PassGraph::PassNode& node = m_cls.passes[p];
        std::array<emu::QuadCoords, 4> coords{};
        for (size_t s = 0; s < node.info.stages.size() && s < 4; ++s) coords[s] = node.info.stages[s].coords;
        std::array<float, emu::kAttrCount> attr{};
        if (!quadAttributes(dp.width, dp.height, coords, int(dp.x), int(dp.y), attr)) {
            m_error = "pass " + dp.pass + ": the quad does not cover pixel " + std::to_string(dp.x) + "," + std::to_string(dp.y);
            return false;
        }
        const bool fx = ps11::isFixedPoint(m_cls.hw.precision);
        for (size_t s = 0; s < node.info.stages.size(); ++s) {
            const PassStage& st = node.info.stages[s];
            const PassGraph::TextureNode& t = m_cls.textures[st.texture.index];
            DebugSource src;
            src.role = "t" + std::to_string(s);
            src.stage = int(s);
            src.texture = t.name;
            src.width = t.desc.width, src.height = t.desc.height;
            src.u = attr[size_t(emu::attrTex(int(s), 0))];
            src.v = attr[size_t(emu::attrTex(int(s), 1))];
            src.linear = st.filter != D3DTEXF_POINT;
            src.texels = tapTexels(src.u, src.v, src.width, src.height, src.linear, fx);
            dp.sources.push_back(src);
        }
        if (node.info.blend != Blend::None) {
            DebugSource src;
            src.role = "target";
            src.texture = dp.target;
            src.width = dp.width, src.height = dp.height;
            src.texels = {{dp.x, dp.y, 1}};
            dp.sources.push_back(src);
        }
        // The differences first, then the walk: the source that carries the largest difference
        // first (visit grows m_out.passes, never dp).
        std::vector<uint32_t> tex;
        for (DebugSource& src : dp.sources) {
            tex.push_back(src.stage >= 0 ? node.info.stages[size_t(src.stage)].texture.index : target);
            measure(p, tex.back(), src);
        }
        std::vector<size_t> order(dp.sources.size());
        for (size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::stable_sort(order.begin(), order.end(),
                         [&](size_t a, size_t b) { return dp.sources[a].levels > dp.sources[b].levels; });
        for (size_t i : order)
            if (!follow(p, tex[i], dp.sources[i])) return false;
        const ps11::Program* prog = program(node.info.shader);
        if (!prog) return false;
        Traced a, b;
        if (!tracePass(m_cls, *prog, p, target, int(dp.x), int(dp.y), attr, a, m_error) ||
            !tracePass(m_ideal, *prog, p, target, int(dp.x), int(dp.y), attr, b, m_error))
            return false;
        ps11::DebugInputs di;
        di.constants = m_cls.constants;
        for (const auto& [reg, value] : node.info.constants)
            if (reg >= 0 && reg < 8) di.constants[size_t(reg)] = value;
        for (size_t c = 0; c < 4; ++c) {
            di.color[0][c] = attr[size_t(emu::kAttrDiffuse) + c];
            di.color[1][c] = attr[size_t(emu::kAttrSpecular) + c];
            for (size_t t = 0; t < size_t(ps11::kMaxTexCoordSets); ++t) di.texcoord[t][c] = attr[size_t(emu::attrTex(int(t), int(c)))];
        }
        for (auto& v : di.stage) v = {0, 0, 0, 1};
        // Each stage's lookup as the class's trace made it (ps_1_1 `tex t#`: the destination is the stage).
        for (const ps11::TraceStep& s : a.steps) {
            const ps11::Instruction& inst = prog->instructions[size_t(s.instruction)];
            if (ps11::samplesStage(inst.opcode()) && inst.dst.index < ps11::kMaxTextureStages)
                di.stage[size_t(inst.dst.index)] = s.value;
        }
        for (const DebugSource& src : dp.sources)
            if (src.stage >= 0 && src.stage < ps11::kMaxTextureStages) di.texelsDiffer[size_t(src.stage)] = src.levels > 0;
        dp.steps = ps11::debugSteps(*prog, m_cls.hw, di, a.steps, b.steps, a.sampler);
        dp.firstDivergence = ps11::firstDivergence(dp.steps);
        dp.traced = true;
        dp.tracedEmulated = a.stored;
        dp.tracedIdeal = b.stored;
        return true;
    }

    bool stretchPass(uint32_t p, uint32_t target, DebugPass& dp) {
        const PassGraph::PassNode& node = m_cls.passes[p];
        if (node.reads.empty()) return true;
        const uint32_t t = node.reads[0].index;
        const PassGraph::TextureNode& sn = m_cls.textures[t];
        (void)target;
        emu::StretchCall call;
        call.sourceRect = {0, 0, sn.desc.width, sn.desc.height};
        call.destRect = {0, 0, dp.width, dp.height};
        call.linear = !node.info.stages.empty() && node.info.stages[0].filter == D3DTEXF_LINEAR;
        call.fixedPoint = ps11::isFixedPoint(m_cls.hw.precision);
        const emu::StretchTap tx = emu::stretchTaps(call, true)[dp.x], ty = emu::stretchTaps(call, false)[dp.y];
        DebugSource src;
        src.role = "source";
        src.texture = sn.name;
        src.width = sn.desc.width, src.height = sn.desc.height;
        src.u = float((double(dp.x) + 0.5) / dp.width), src.v = float((double(dp.y) + 0.5) / dp.height);
        src.linear = call.linear;
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
                const double w = (i ? tx.w1 : 1 - tx.w1) * (j ? ty.w1 : 1 - ty.w1);
                if (w <= 0 && !(i == 0 && j == 0)) continue;
                const uint32_t x = uint32_t(i ? tx.i1 : tx.i0), y = uint32_t(j ? ty.i1 : ty.i0);
                auto same = std::find_if(src.texels.begin(), src.texels.end(),
                                         [&](const DebugTexel& d) { return d.x == x && d.y == y; });
                if (same != src.texels.end())
                    same->weight += w;
                else
                    src.texels.push_back({x, y, w});
            }
        std::stable_sort(src.texels.begin(), src.texels.end(),
                         [](const DebugTexel& a, const DebugTexel& b) { return a.weight > b.weight; });
        measure(p, t, src);
        dp.sources.push_back(src);
        return follow(p, t, dp.sources.back());
    }

    const FrameDebugRequest& m_rq;
    FrameRun& m_cls;
    FrameRun& m_ideal;
    FrameDebug& m_out;
    std::map<uint32_t, int> m_seen;  // pass → index in m_out.passes
    std::map<std::string, ps11::Program> m_programs;
};

}  // namespace

bool debugFrame(const FrameDebugRequest& rq, FrameDebug& out, std::string& error) {
    out = FrameDebug{};
    if (!rq.technique) {
        error = "no technique";
        return false;
    }
    const uint32_t width = rq.image ? rq.image->width : rq.width, height = rq.image ? rq.image->height : rq.height;
    if (rq.x >= width || rq.y >= height) {
        error = "--pixel " + std::to_string(rq.x) + "," + std::to_string(rq.y) + " is outside the " +
                std::to_string(width) + "x" + std::to_string(height) + " frame";
        return false;
    }
    FrameRun cls, ideal;
    if (!runFrames(rq, width, height, cls, ideal, error)) return false;
    out.technique = std::string(rq.technique->name());
    out.hardware = std::string(cls.hw.hardware->name);
    out.fx = ps11::isFixedPoint(cls.hw.precision);
    out.width = width, out.height = height;
    out.frame = rq.frame;
    out.x = rq.x, out.y = rq.y;
    // The final pass: the last live pass that writes the output.
    int final = -1;
    for (size_t p = 0; p < cls.passes.size(); ++p) {
        if (!cls.passes[p].live) continue;
        for (TextureId id : cls.passes[p].writes)
            if (cls.textures[id.index].imported && cls.textures[id.index].name == "output") final = int(p);
    }
    if (final < 0) {
        error = "the frame has no pass that writes its output";
        return false;
    }
    Walk walk(rq, cls, ideal, out);
    if (walk.visit(uint32_t(final), rq.x, rq.y) < 0) {
        error = walk.m_error;
        return false;
    }
    // The order the frame ran them in: by pass, then row, then column.
    std::vector<size_t> order(out.passes.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const DebugPass &p = out.passes[a], &q = out.passes[b];
        return std::tie(p.graphIndex, p.y, p.x) < std::tie(q.graphIndex, q.y, q.x);
    });
    std::vector<int> newIndex(order.size());
    for (size_t i = 0; i < order.size(); ++i) newIndex[order[i]] = int(i);
    std::vector<DebugPass> sorted;
    for (size_t i : order) sorted.push_back(std::move(out.passes[i]));
    for (DebugPass& p : sorted)
        for (DebugSource& s : p.sources)
            if (s.from >= 0) s.from = newIndex[size_t(s.from)];
    out.passes = std::move(sorted);
    for (size_t i = 0; i < out.passes.size(); ++i)
        if (out.mostError < 0 || out.passes[i].added > out.passes[size_t(out.mostError)].added) out.mostError = int(i);
    return true;
}

}  // namespace glare
