// `ps11 test`, the executor part: a file's `eval` commands run the validated [pixel shader] for
// one pixel on the executor (emu backend; the GL backend comes with the device) with the file's
// precision, max value, [constants], [stage N] state and [texture N]/[sampler N] textures, and
// `probe eval` compares r0 with an absolute tolerance. Draws and pixel probes run on the emu device
// (runner/test_draw.cpp); on the gl backend every command is counted as not runnable yet.
#include "runner/test_eval.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <optional>
#include <variant>

#include "ps11/diagnostics.h"
#include "ps11/texture.h"
#include "ps11/testfile_textures.h"
#include "ps11/texture_sampler.h"
#include "emu/format.h"
#include "emu/renderer.h"
#include "ps11/opcodes.h"
#include "runner/test_draw.h"

namespace ps11test {

using namespace ps11;
namespace {

std::string where(const std::string& path, uint32_t line) { return path + ":" + std::to_string(line); }

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

// "0.5 0.5 0.5 1" (n components).
std::string floats(const Vec4& v, int n) {
    std::string s;
    for (int c = 0; c < n; ++c) s += (c ? " " : "") + num(v[c]);
    return s;
}

std::string describeOutcome(const EvalOutcome& o, int n, Precision p) {
    if (o.killed) return "killed";
    std::string s = floats(o.color, n);
    if (isFixedPoint(p)) {
        s += " = [";
        for (int c = 0; c < n; ++c) s += (c ? " " : "") + std::to_string(o.grid[c]);
        s += "]/" + std::to_string(gridScale(p));
    }
    return s;
}

// Checks one eval probe against the last eval; returns the failure text ("" = passed).
std::string checkProbe(const Probe& probe, const EvalOutcome& got, Precision p) {
    if (probe.kind == ProbeKind::EvalDepth) {
        if (got.killed) return "expected depth " + num(probe.depth) + ", got a killed pixel";
        if (!got.hasDepth) return "expected depth " + num(probe.depth) + ", but the shader does not write depth";
        const double diff = std::fabs(double(got.depth) - double(probe.depth));
        if (diff <= double(probe.tolerance)) return "";
        return "expected depth " + num(probe.depth) + " tol " + num(probe.tolerance) + ", got " + num(got.depth);
    }
    if (probe.kind == ProbeKind::EvalKilled) {
        if (got.killed) return "";
        return "expected killed, got " + describeOutcome(got, 4, p) + " (not killed)";
    }
    int n = probe.alpha ? 4 : 3;
    bool ok = !got.killed;
    for (int c = 0; ok && c < n; ++c) {
        double diff = std::fabs(double(got.color[c]) - double(probe.expected.rgba[c]));
        if (!(diff <= double(probe.tolerance))) ok = false;  // NaN never passes
    }
    if (ok) return "";
    return std::string("expected ") + (probe.alpha ? "rgba " : "rgb ") + floats(probe.expected.rgba, n) + " tol " +
           num(probe.tolerance) + ", got " + describeOutcome(got, n, p);
}

bool isDeviceCommand(const TestCommand& cmd) {
    if (std::holds_alternative<DrawQuad>(cmd.op) || std::holds_alternative<DrawPrimitives>(cmd.op)) return true;
    if (const Probe* probe = std::get_if<Probe>(&cmd.op))
        return !isEvalProbe(probe->kind);
    return false;
}

// The executor and sampler of one file, built on the first eval.
struct EvalState {
    std::unique_ptr<Executor> executor;
    std::unique_ptr<Sampler> sampler;
};

bool prepare(const TestFile& file, const std::string& path, const Program& program, const CommandRunOptions& opts,
             EvalState& state) {
    const ExecutorOptions eo = executorOptionsFor(opts.hardware);
    Diagnostics diags;
    if (opts.shaderDiags) {
        diags = *opts.shaderDiags;
        diags.clear();
    }
    state.executor = Executor::create(program, eo, diags);
    if (!state.executor) {
        std::cout << where(path, file.pixelShader.line) << ": the executor cannot run this shader (hardware "
                  << opts.hardware.describe() << "):\n"
                  << diags.formatAll();
        return false;
    }
    for (const ConstantDesc& c : file.constants) state.executor->setConstant(c.index, c.value);
    for (const StageDesc& s : file.stages)
        state.executor->setStageState(s.stage, stageStateOf(s, file.texture(s.stage)));
    std::string error;
    state.sampler = makeTestSampler(file, path, opts.hardware, error);
    if (!state.sampler) {
        std::cout << error << "\n";
        return false;
    }
    if (opts.verbose) {
        uint32_t sampled = state.executor->sampledStages();
        for (int stage = 0; stage < kMaxTextureStages; ++stage)
            if ((sampled & (1u << stage)) && !file.texture(stage))
                std::cout << where(path, file.pixelShader.line) << ": note: the shader samples stage " << stage
                          << ", which has no [texture " << stage << "]; D3D returns (0, 0, 0, 1) there\n";
    }
    return true;
}

// Counts a checked probe: passed, failed, todo, or a todo that passes (an error). Messages name
// the hardware class, profile and MaxValue that ran.
void countProbe(const std::string& path, const TestCommand& cmd, const std::string& failure, bool todo,
                const HardwareConfig& hw, bool verbose, CommandTally& tally, const std::string& got = "") {
    if (failure.empty() && todo) {
        std::cout << where(path, cmd.line) << ": error: todo probe passed (remove the todo)"
                  << (got.empty() ? "" : ": " + got) << " (hardware " << hw.describe() << ")\n";
        ++tally.probesFailed;
    } else if (failure.empty()) {
        ++tally.probesPassed;
    } else if (todo) {
        ++tally.probesTodo;
        if (verbose)
            std::cout << where(path, cmd.line) << ": todo: " << failure << " (hardware " << hw.describe() << ")\n";
    } else {
        std::cout << where(path, cmd.line) << ": probe failed: " << failure << " (hardware " << hw.describe()
                  << ")\n";
        ++tally.probesFailed;
    }
}

}  // namespace

EvalOutcome evalOnePixel(const Executor& executor, Sampler& sampler, const EvalInputs& in, ExecutorStats* stats) {
    PixelInputs inputs;
    inputs.count = 1;
    inputs.quads = false;
    for (int r = 0; r < 2; ++r)
        for (int c = 0; c < 4; ++c) inputs.color[r][c] = in.color[r] ? &(*in.color[r])[c] : nullptr;
    for (int r = 0; r < kMaxTexCoordSets; ++r)
        for (int c = 0; c < 4; ++c) inputs.texcoord[r][c] = in.texture[r] ? &(*in.texture[r])[c] : nullptr;
    EvalOutcome out;
    float depth = 0;
    uint8_t killed = 0;
    PixelOutputs outputs;
    for (int c = 0; c < 4; ++c) {
        outputs.color[c] = &out.color[c];
        outputs.grid[c] = &out.grid[c];
    }
    outputs.killed = &killed;
    outputs.depth = &depth;
    executor.run(inputs, sampler, outputs, stats);
    out.killed = killed != 0;
    out.hasDepth = executor.writesDepth();
    out.depth = depth;
    return out;
}

StageState stageStateOf(const StageDesc& stage, const TextureDesc* texture) {
    StageState s;
    s.bumpMat = stage.bumpEnvMat.value;
    s.lumScale = stage.lScale.value;
    s.lumOffset = stage.lOffset.value;
    s.transformFlags = stage.transformFlags.value.bits;
    s.coordComponents = 4;
    s.textureDimensions = texture && texture->isVolume() ? 3 : 2;
    return s;
}

std::unique_ptr<Sampler> makeTestSampler(const TestFile& file, const std::string& path,
                                         const HardwareConfig& hardware, std::string& error) {
    auto sampler = std::make_unique<TextureSampler>();
    sampler->setWeightBits(hardware.weightBits);
    for (const TextureDesc& t : file.textures) {
        std::string why;
        std::optional<Texture> texture = textureFromDesc(t, hardware.hardware->signedDecode, why);
        if (!texture) {
            error = where(path, t.line) + ": cannot build [texture " + std::to_string(t.stage) + "]: " + why;
            return nullptr;
        }
        sampler->bind(t.stage, std::make_shared<const Texture>(std::move(*texture)));
    }
    // A missing [sampler N] keeps D3D9's defaults (SamplerState{}).
    for (const SamplerDesc& sd : file.samplers) sampler->setSamplerState(sd.stage, samplerStateFromDesc(sd));
    return sampler;
}

// --backend both: keeps the emu renderer's target after a draw; on gl compares with it pixel by
// pixel (8-bit levels, or values on float targets) and reports a draw past the cross-check's
// target (more than one level, or 1e-4 on float targets) as a disagreement.
// --backend both: an eval's outcome on gl against the executor's (r0's grid integers in fx
// profiles, float32 values otherwise, the kill and the depth): any difference is a disagreement.
static void compareEval(const std::string& path, const TestCommand& cmd, const EvalOutcome& emu, const EvalOutcome& gl,
                        Precision p, bool native, CommandTally& tally) {
    ++tally.comparedDraws;
    ++tally.comparedPixels;
    bool same = emu.killed == gl.killed && emu.hasDepth == gl.hasDepth && (!emu.hasDepth || emu.depth == gl.depth);
    double d = 0;
    if (!emu.killed && !gl.killed)
        for (int c = 0; c < 4; ++c) {
            const double a = emu.color[size_t(c)], b = gl.color[size_t(c)];
            d = std::max(d, a == b ? 0.0 : std::fabs(a - b) * (isFixedPoint(p) ? 255.0 : 1.0));
            if (isFixedPoint(p) ? emu.grid[size_t(c)] != gl.grid[size_t(c)] : a != b) same = false;
        }
    tally.maxDiff = std::max(tally.maxDiff, d);
    if (same) {
        ++tally.exactPixels;
        return;
    }
    if (d > (isFixedPoint(p) ? 1.0 : 1e-4) || emu.killed != gl.killed || emu.hasDepth != gl.hasDepth) {
        ++tally.overOnePixels;
        if (native) {
            ++tally.nativeDrawsPastTarget;
            return;
        }
        ++tally.disagreements;
        std::cout << where(path, cmd.line) << ": disagreement: the eval gives " << describeOutcome(gl, 4, p)
                  << " on gl and " << describeOutcome(emu, 4, p) << " on emu\n";
    }
}

static void compareDraw(const std::string& path, const TestCommand& cmd, bool gl, bool native, DrawRunner& device,
                        std::vector<Vec4>& emuTarget, CommandTally& tally) {
    std::vector<Vec4> pixels;
    std::string error;
    if (!device.targetPixels(pixels, error)) return;
    if (!gl) {
        emuTarget = std::move(pixels);
        return;
    }
    if (emuTarget.size() != pixels.size()) return;
    const bool values = device.floatTarget();
    uint64_t exact = 0, overOne = 0;
    double maxDiff = 0;
    size_t firstBad = pixels.size();
    for (size_t i = 0; i < pixels.size(); ++i) {
        double d = 0;
        for (int c = 0; c < 4; ++c) {
            const double a = pixels[i][size_t(c)], b = emuTarget[i][size_t(c)];
            const double diff = (a == b || (a != a && b != b)) ? 0.0 : std::fabs(a - b);
            d = std::max(d, diff != diff ? 1e30 : diff);
        }
        exact += d == 0;
        if (d > (values ? 1e-4 : 1.0)) {
            ++overOne;
            if (firstBad == pixels.size()) firstBad = i;
        }
        maxDiff = std::max(maxDiff, d);
    }
    ++tally.comparedDraws;
    tally.comparedPixels += pixels.size();
    tally.exactPixels += exact;
    tally.overOnePixels += overOne;
    tally.maxDiff = std::max(tally.maxDiff, maxDiff);
    if (overOne && native) {
        ++tally.nativeDrawsPastTarget;
    } else if (overOne) {
        ++tally.disagreements;
        const uint32_t w = std::max<uint32_t>(device.width(), 1);
        std::cout << where(path, cmd.line) << ": disagreement: gl and emu differ past the target on " << overOne << " of "
                  << pixels.size() << " pixels (max |d| " << maxDiff << (values ? "" : " levels") << "), first at ("
                  << firstBad % w << ", " << firstBad / w << ")\n";
    }
}

void runCommands(const TestFile& file, const std::string& path, const Program* program,
                 const CommandRunOptions& opts, CommandTally& tally) {
    const Precision p = opts.hardware.precision;
    const HardwareClass& hw = *opts.hardware.hardware;
    EvalState state;
    bool prepared = false;
    const bool both = (opts.backends & kBackendEmu) && (opts.backends & kBackendGl);
    // --backend both: the emu renderer's target after each draw and each probe's outcome, by
    // command index, for the gl pass to compare with.
    std::vector<std::vector<Vec4>> emuTargets(file.commands.size());
    std::vector<int8_t> emuProbePassed(file.commands.size(), -1);
    std::vector<std::optional<EvalOutcome>> emuEvals(file.commands.size());
    // A probe's outcome on emu is kept; on gl one that differs is a disagreement. Failures on gl
    // are marked.
    auto crossCheckProbe = [&](size_t ci, const TestCommand& cmd, bool gl, std::string& failure) {
        const int8_t passed = failure.empty() ? 1 : 0;
        if (both && !gl) emuProbePassed[ci] = passed;
        if (both && gl && emuProbePassed[ci] >= 0 && emuProbePassed[ci] != passed) {
            std::cout << where(path, cmd.line) << ": disagreement: the probe " << (passed ? "passes" : "fails")
                      << " on gl and " << (passed ? "fails" : "passes") << " on emu\n";
            ++tally.disagreements;
        }
        if (gl && !failure.empty()) failure = "[gl] " + failure;
    };
    // Native mode: the gl side's probes are measured: one that would fail is counted, not failed.
    auto measured = [&](bool gl, const TestCommand& cmd, std::string& failure) {
        if (!(gl && opts.glNative)) return false;
        if (!failure.empty()) {
            ++tally.nativeProbesDiffering;
            if (opts.verbose) std::cout << where(path, cmd.line) << ": native: " << failure << "\n";
        } else {
            ++tally.probesPassed;
        }
        return true;
    };
    std::unique_ptr<RendererEval> glEval;
    for (Backend backend : {Backend::Emu, Backend::Gl}) {
        if (!(opts.backends & (1u << unsigned(backend)))) continue;
        const bool gl = backend == Backend::Gl;
        // The last thing a probe looks at: an eval's r0 or the device's render target.
        std::optional<EvalOutcome> last;
        std::unique_ptr<DrawRunner> device;
        bool deviceFailed = false;
        for (size_t ci = 0; ci < file.commands.size(); ++ci) {
            const TestCommand& cmd = file.commands[ci];
            if (!cmd.onlyIf.matches(backend, p, hw)) continue;
            if (gl && !opts.glRenderer) {
                ++tally.pendingGl;  // no GL renderer
                continue;
            }
            if (isDeviceCommand(cmd)) {
                if (deviceFailed) continue;
                std::string error;
                if (!device) {
                    device = DrawRunner::create(file, path, program, opts.hardware, error, true,
                                                gl ? opts.glRenderer : RendererFactory{}, opts.skipTiles);
                    if (!device) {
                        std::cout << error << (gl ? " [gl]" : "") << "\n";
                        deviceFailed = tally.error = true;
                        continue;
                    }
                }
                if (!std::holds_alternative<Probe>(cmd.op)) {
                    if (!device->draw(cmd, error)) {
                        std::cout << error << (gl ? " [gl]" : "") << "\n";
                        deviceFailed = tally.error = true;
                        continue;
                    }
                    if (both) compareDraw(path, cmd, gl, opts.glNative, *device, emuTargets[ci], tally);
                    continue;
                }
                std::string failure = device->probe(std::get<Probe>(cmd.op), error);
                if (!error.empty()) {
                    std::cout << error << (gl ? " [gl]" : "") << "\n";
                    deviceFailed = tally.error = true;
                    continue;
                }
                if (measured(gl, cmd, failure)) continue;
                crossCheckProbe(ci, cmd, gl, failure);
                countProbe(path, cmd, failure, cmd.isTodo(backend, p, hw), opts.hardware, opts.verbose, tally);
                continue;
            }
            if (const Eval* eval = std::get_if<Eval>(&cmd.op)) {
                if (!program) continue;  // the reader rejects evals without a [pixel shader]
                if (!prepared) {
                    prepared = true;
                    if (!prepare(file, path, *program, opts, state)) {
                        tally.error = true;
                        return;
                    }
                }
                EvalInputs in;
                for (int r = 0; r < 2; ++r)
                    if (eval->color[r].isSet()) in.color[r] = &eval->color[r].value;
                for (int r = 0; r < kMaxTexCoordSets; ++r)
                    if (eval->texture[r].isSet()) in.texture[r] = &eval->texture[r].value;
                if (gl) {
                    if (!glEval) {
                        std::string error;
                        glEval = RendererEval::create(file, path, *program, opts.hardware, opts.glRenderer, error);
                        if (!glEval) {
                            std::cout << error << " [gl]\n";
                            tally.error = true;
                            return;
                        }
                    }
                    std::string error;
                    last = glEval->eval(in, error);
                    if (!last) {
                        std::cout << where(path, cmd.line) << ": " << error << " [gl]\n";
                        tally.error = true;
                        return;
                    }
                    if (both && emuEvals[ci]) compareEval(path, cmd, *emuEvals[ci], *last, p, opts.glNative, tally);
                } else {
                    last = evalOnePixel(*state.executor, *state.sampler, in, &tally.stats);
                    if (both) emuEvals[ci] = *last;
                }
                ++tally.evals;
                continue;
            }
            const Probe& probe = std::get<Probe>(cmd.op);
            if (!last) {
                std::cout << where(path, cmd.line) << ": probe failed: no eval ran before this probe (hardware "
                          << opts.hardware.describe() << ")\n";
                ++tally.probesFailed;
                continue;
            }
            std::string failure = checkProbe(probe, *last, p);
            if (measured(gl, cmd, failure)) continue;
            crossCheckProbe(ci, cmd, gl, failure);
            countProbe(path, cmd, failure, cmd.isTodo(backend, p, hw), opts.hardware, opts.verbose, tally,
                       describeOutcome(*last, probe.alpha ? 4 : 3, p));
        }
        if (device) {
            const DrawTally& d = device->tally();
            tally.draws.draws += d.draws;
            tally.draws.pixelsShaded += d.pixelsShaded;
            tally.draws.pixelsWritten += d.pixelsWritten;
            tally.draws.texelsFetched += d.texelsFetched;
            tally.draws.instructions += d.instructions;
            tally.draws.milliseconds += d.milliseconds;
            tally.draws.tilesShaded += d.tilesShaded;
            tally.draws.tilesFilled += d.tilesFilled;
            tally.draws.tilesCopied += d.tilesCopied;
            tally.draws.tilesSkipped += d.tilesSkipped;
        }
    }
    if (state.sampler) tally.texelsFetched = state.sampler->texelsFetched();
}

struct RendererEval::Impl {
    std::unique_ptr<emu::Renderer> renderer;
    emu::DrawCall call;
    bool writesDepth = false;
    emu::Image color, depth;
    uint64_t generation = 0;  // of the two surfaces, as a front would count them
};

RendererEval::~RendererEval() = default;

std::unique_ptr<RendererEval> RendererEval::create(const TestFile& file, const std::string& path,
                                                   const Program& program, const HardwareConfig& hardware,
                                                   const RendererFactory& factory, std::string& error) {
    std::unique_ptr<RendererEval> r(new RendererEval);
    r->m_impl = std::make_unique<Impl>();
    Impl& m = *r->m_impl;
    m.renderer = factory();
    if (!m.renderer) {
        error = path + ": no renderer for evals";
        return nullptr;
    }
    emu::DrawCall& call = m.call;
    call.hardware = hardware;
    call.program.program = &program;
    call.program.key = 1;
    for (const ConstantDesc& c : file.constants) call.program.constants[size_t(c.index)] = c.value;
    for (const StageDesc& sd : file.stages) call.program.stages[size_t(sd.stage)] = stageStateOf(sd, file.texture(sd.stage));
    for (const TextureDesc& t : file.textures) {
        std::string why;
        std::optional<Texture> texture = textureFromDesc(t, hardware.hardware->signedDecode, why);
        if (!texture) {
            error = where(path, t.line) + ": cannot build [texture " + std::to_string(t.stage) + "]: " + why;
            return nullptr;
        }
        call.textures[size_t(t.stage)] = std::make_shared<const Texture>(std::move(*texture));
    }
    for (const SamplerDesc& sd : file.samplers) call.samplers[size_t(sd.stage)] = samplerStateFromDesc(sd);
    for (const Instruction& ins : program.instructions)
        if (ins.info && replacesDepth(ins.opcode())) m.writesDepth = true;
    auto image = [](emu::Image& img, emu::D3DFORMAT f) {
        img.format = emu::formatInfo(f);
        img.width = img.height = 1;
        img.rowPitch = img.format->bytes;
        img.slicePitch = img.rowPitch;
        img.bytes.assign(img.format->bytes, 0);
    };
    image(m.color, emu::D3DFMT_A32B32G32R32F);
    image(m.depth, emu::D3DFMT_D32F_LOCKABLE);
    call.merge.precision = hardware.precision;
    if (m.writesDepth) {
        call.merge.depthTest = true;
        call.merge.depthWrite = true;
        call.merge.depthFunc = emu::D3DCMP_ALWAYS;
    }
    call.target.color = &m.color;
    call.target.depth = m.writesDepth ? &m.depth : nullptr;
    call.clip = emu::ClipRect{0, 0, 1, 1};
    call.usedAttributes = emu::attributesRead(program);
    call.primitiveCount = 1;
    return r;
}

std::optional<EvalOutcome> RendererEval::eval(const EvalInputs& in, std::string& error) {
    Impl& m = *m_impl;
    emu::ScreenTriangle tri;
    // Pixel (0, 0) strictly inside; every vertex carries the same attributes.
    const double xy[3][2] = {{-1, -1}, {3, -1}, {-1, 3}};
    for (int v = 0; v < 3; ++v) {
        emu::ScreenVertex& sv = tri.v[size_t(v)];
        sv.x = xy[v][0], sv.y = xy[v][1];
        for (int r = 0; r < 2; ++r)
            for (int c = 0; c < 4; ++c)
                sv.attr[size_t((r ? emu::kAttrSpecular : emu::kAttrDiffuse) + c)] = in.color[size_t(r)] ? (*in.color[size_t(r)])[size_t(c)] : 0.0f;
        for (int t = 0; t < kMaxTexCoordSets; ++t)
            for (int c = 0; c < 4; ++c)
                sv.attr[size_t(emu::attrTex(t, c))] = in.texture[size_t(t)] ? (*in.texture[size_t(t)])[size_t(c)] : 0.0f;
    }
    m.call.assemble = [&tri](uint32_t, uint32_t, std::vector<emu::ScreenTriangle>& out) { out.push_back(tri); };
    std::fill(m.color.bytes.begin(), m.color.bytes.end(), uint8_t(0));
    // The surfaces as a front hands them to a renderer (emu/renderer.h): cleared here, so newer
    // than any copy the renderer keeps; read back after the draw.
    m.generation += 2;
    m.call.colorSurface = emu::SurfaceDesc{1, 0, &m.color, m.generation, m.generation + 1};
    if (m.writesDepth) m.call.depthSurface = emu::SurfaceDesc{2, 0, &m.depth, m.generation, m.generation + 1};
    emu::DrawStats stats;
    emu::CallError rerr;
    if (!m.renderer->draw(m.call, stats, rerr)) {
        error = rerr.code + " " + rerr.message;
        return std::nullopt;
    }
    if (m.renderer->keepsCopies()) {
        m.renderer->readBack(m.call.colorSurface);
        if (m.writesDepth) m.renderer->readBack(m.call.depthSurface);
    }
    EvalOutcome out;
    out.killed = stats.pixelsWritten == 0;
    const Precision p = m.call.hardware.precision;
    float v[4];
    std::memcpy(v, m.color.bytes.data(), sizeof v);
    for (int c = 0; c < 4; ++c) {
        out.color[size_t(c)] = v[c];
        // fx: the float target holds float(n / G); n is the nearest grid integer.
        if (isFixedPoint(p)) out.grid[size_t(c)] = int32_t(std::lround(double(v[c]) * gridScale(p)));
    }
    out.hasDepth = m.writesDepth;
    if (m.writesDepth) std::memcpy(&out.depth, m.depth.bytes.data(), sizeof(float));
    return out;
}

}  // namespace ps11test
