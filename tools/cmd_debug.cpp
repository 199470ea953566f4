// `ps11 debug` (tools/cmd_debug.h): one pixel of a shader instruction by instruction on the
// emulated class beside `ideal`. Both run the executor's generic path with a trace
// (Executor::trace); the interval evaluator over the pixel's own inputs (one point each) says
// what each write step of the class did — rounded off the grid, clamped at MaxValue, cut by
// _sat — which names why the two part.
#include "tools/cmd_debug.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "ps11/debug_steps.h"
#include "ps11/decoded_program.h"
#include "ps11/disassembler.h"
#include "ps11/formats.h"
#include "ps11/intervals.h"
#include "ps11/opcodes.h"
#include "tools/cli_util.h"
#include "tools/cmd_eval.h"
#include "glare/frame_debug.h"
#include "glare/scene.h"
#include "emu/image_file.h"

namespace ps11 {
namespace {

constexpr const char* kUsage =
    "usage: ps11 debug SHADER.psh [v0=r,g,b,a] [v1=...] [t0=u,v,w,q] ... [c0=x,y,z,w] ...\n"
    "                  [--tex0 [FORMAT:]WORD] ... [--hardware H] [--json]\n"
    "  runs one pixel as `ps11 eval` does (the same inputs) on the hardware class and on `ideal`,\n"
    "  and prints every instruction's destination in both, why they differ (round, clamp,\n"
    "  saturate, signed_decode, filter_weight) and the first instruction where they part by more\n"
    "  than one 8-bit level\n"
    "       ps11 debug --technique T (--scene S | --in IMG) --pixel X,Y [--frame N] [--size WxH]\n"
    "                  [--quality Q] [--set name=value]... [--exposure STOPS] [--hardware H] [--json]\n"
    "  follows one output pixel of a glare frame back through the passes that made it: each pass's\n"
    "  trace at the texels that mattered, the class beside ideal, and the pass that added the most error\n";

// One pixel's inputs as the executor takes them (lane 0).
struct OnePixel {
    float color[2][4] = {};
    float tc[kMaxTexCoordSets][4] = {};
    PixelInputs in;
    explicit OnePixel(const ps11test::EvalInputs& e) {
        in.count = 1;
        for (int v = 0; v < 2; ++v)
            for (int c = 0; c < 4; ++c) {
                color[v][c] = e.color[size_t(v)] ? (*e.color[size_t(v)])[size_t(c)] : 0.0f;
                in.color[v][c] = &color[v][c];
            }
        for (int t = 0; t < kMaxTexCoordSets; ++t)
            for (int c = 0; c < 4; ++c) {
                tc[t][c] = e.texture[size_t(t)] ? (*e.texture[size_t(t)])[size_t(c)] : 0.0f;
                in.texcoord[t][c] = &tc[t][c];
            }
    }
};

struct Run {
    std::vector<TraceStep> steps;
    float r0[4] = {};
    uint8_t killed = 0;
};

Run trace(const Executor& e, Sampler& s, const OnePixel& px) {
    Run r;
    PixelOutputs out;
    for (int c = 0; c < 4; ++c) out.color[c] = &r.r0[c];
    out.killed = &r.killed;
    e.trace(px.in, s, out, r.steps);
    return r;
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4f", v);
    return buf;
}

std::string levelText(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", v);
    return buf;
}

}  // namespace

nlohmann::ordered_json debugStepsJson(const std::vector<DebugStep>& rows, bool fx) {
    nlohmann::ordered_json steps = nlohmann::ordered_json::array();
    for (const DebugStep& r : rows) {
        nlohmann::ordered_json s;
        s["line"] = r.line;
        s["text"] = r.text;
        if (r.writes) {
            s["emulated"] = r.emulated;
            if (fx) s["grid"] = r.grid;
            s["ideal"] = r.ideal;
        } else {
            s["emulated"] = nullptr;
            s["ideal"] = nullptr;
        }
        s["levels"] = r.levels;
        s["why"] = r.why;
        steps.push_back(s);
    }
    return steps;
}

void printDebugSteps(const std::vector<DebugStep>& rows, const std::string& hardware, bool fx) {
    const int firstDiv = firstDivergence(rows);
    std::printf("   %-5s %-26s %-36s %-32s %-6s %s\n", "line", "instruction", hardware.c_str(), "ideal", "Δ lvl", "why");
    for (size_t k = 0; k < rows.size(); ++k) {
        const DebugStep& r = rows[k];
        std::string e, i;
        for (size_t c = 0; c < 4; ++c) {
            if (!r.writes || !((r.mask >> c) & 1)) {
                e += c ? "       " : "      ", i += c ? "       " : "      ";
                continue;
            }
            e += (c ? " " : "") + num(r.emulated[c]);
            i += (c ? " " : "") + num(r.ideal[c]);
        }
        if (fx && r.writes) {
            e += " [";
            for (size_t c = 0; c < 4; ++c)
                if ((r.mask >> c) & 1) e += (e.back() == '[' ? "" : " ") + std::to_string(r.grid[c]);
            e += "]";
        }
        std::string why;
        for (const std::string& w : r.why) why += (why.empty() ? "" : ", ") + w;
        if (why.empty() && r.levels > 0) why = "(from its sources)";
        std::string text = r.text;
        if (text.size() > 26) text = text.substr(0, 25) + "~";
        std::printf("%s %-5u %-26s %-36s %-32s %-6s %s\n", int(k) == firstDiv ? ">>" : "  ", r.line, text.c_str(),
                    e.c_str(), r.writes ? i.c_str() : "", r.writes ? levelText(r.levels).c_str() : "", why.c_str());
    }
    if (firstDiv >= 0)
        std::cout << ">> line " << rows[size_t(firstDiv)].line
                  << ": the first instruction where the class and ideal part by more than one 8-bit level\n";
    else
        std::cout << "the class stays within one 8-bit level of ideal at every instruction\n";
}

namespace {

int frameUsage(const std::string& msg) {
    std::cerr << "ps11: debug: " << msg << "\n" << kUsage;
    return cli::kUsage;
}

std::string rgba(const std::array<float, 4>& v) {
    std::string s;
    for (size_t c = 0; c < 4; ++c) s += (c ? " " : "") + num(v[c]);
    return s;
}

// `ps11 debug --technique …` (glare/frame_debug.h).
int cmdDebugFrame(const std::vector<std::string>& args) {
    glare::FrameDebugRequest rq;
    std::string technique, quality = "published", in, pixel;
    std::vector<std::string> sets;
    bool json = false, sizeGiven = false;
    float exposure = 0;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        std::string v;
        auto value = [&] {
            if (i + 1 >= args.size()) return false;
            v = args[++i];
            return true;
        };
        if (a == "--help" || a == "-h") {
            std::cout << kUsage;
            return cli::kOk;
        } else if (a == "--json") {
            json = true;
        } else if (a == "--technique" || a == "-t") {
            if (!value()) return frameUsage("--technique needs a name");
            technique = v;
        } else if (a == "--scene") {
            if (!value()) return frameUsage("--scene needs a name");
            rq.scene = v;
        } else if (a == "--in") {
            if (!value()) return frameUsage("--in needs an image file");
            in = v;
        } else if (a == "--pixel") {
            if (!value()) return frameUsage("--pixel needs X,Y");
            pixel = v;
        } else if (a == "--frame") {
            if (!value() || !cli::parseCount(v, 0, 9999, rq.frame)) return frameUsage("--frame takes a frame number 0..9999");
        } else if (a == "--size") {
            if (!value() || !cli::parseSize(v, rq.width, rq.height)) return frameUsage("--size takes " + cli::sizeRule());
            sizeGiven = true;
        } else if (a == "--quality") {
            if (!value()) return frameUsage("--quality needs low, medium, high or published");
            quality = v;
        } else if (a == "--set") {
            if (!value()) return frameUsage("--set needs name=value");
            sets.push_back(v);
        } else if (a == "--hardware") {
            if (!value()) return frameUsage("--hardware needs a class");
            rq.hardware = findHardware(v);
            if (!rq.hardware) return frameUsage(unknownHardwareMessage(v));
        } else if (a == "--exposure") {
            const std::optional<float> e = value() ? cli::parseFloat(v) : std::nullopt;
            if (!e || std::fabs(*e) > 64) return frameUsage("--exposure takes stops in -64 .. 64");
            exposure = *e;
        } else {
            return frameUsage(cli::unknownOption(a, {"--technique", "--scene", "--in", "--pixel", "--frame", "--size",
                                                     "--quality", "--set", "--hardware", "--exposure", "--json", "--help"}));
        }
    }
    rq.technique = glare::findTechnique(technique);
    if (!rq.technique) return frameUsage(glare::unknownTechniqueMessage(technique));
    std::optional<glare::Settings> settings = glare::presetSettings(*rq.technique, quality);
    if (!settings) return frameUsage("unknown --quality '" + quality + "' (low, medium, high, published)");
    for (const std::string& s : sets) {
        std::string err;
        if (!glare::applySetting(*rq.technique, *settings, s, err)) return frameUsage(err);
    }
    rq.settings = *settings;
    if (rq.scene.empty() == in.empty()) return frameUsage("give one input: --scene NAME or --in IMAGE");
    if (!in.empty() && sizeGiven) return frameUsage("--size applies to --scene; an --in image keeps its own size");
    {
        const size_t comma = pixel.find(',');
        int x = -1, y = -1;
        if (pixel.empty()) return frameUsage("say which output pixel to follow: --pixel X,Y");
        if (comma == std::string::npos || !cli::parseCount(pixel.substr(0, comma), 0, 1 << 20, x) ||
            !cli::parseCount(pixel.substr(comma + 1), 0, 1 << 20, y))
            return frameUsage("--pixel takes X,Y (whole numbers from 0), not '" + pixel + "'");
        rq.x = uint32_t(x), rq.y = uint32_t(y);
    }
    std::string err;
    if (!in.empty()) {
        std::optional<emu::LoadedImage> loaded = emu::readImage(in, err);
        if (!loaded) {
            std::cerr << "ps11: debug: --in " << err << "\n";
            return cli::kUserError;
        }
        rq.image = loaded->hdr ? emu::exposeUnclamped(loaded->image, exposure) : loaded->image;
    } else if (!glare::makeScene(rq.scene, err)) {
        return frameUsage("--scene: " + err);
    }
    const uint32_t w = rq.image ? rq.image->width : rq.width, h = rq.image ? rq.image->height : rq.height;
    if (w < 8 || h < 8) {
        std::cerr << "ps11: debug: the frame is " << w << "x" << h << "; the techniques need at least 8x8\n";
        return cli::kUserError;
    }
    if (rq.x >= w || rq.y >= h)
        return frameUsage("--pixel " + pixel + " is outside the " + std::to_string(w) + "x" + std::to_string(h) + " frame");
    glare::FrameDebug fd;
    if (!glare::debugFrame(rq, fd, err)) {
        std::cerr << "ps11: debug: " << err << "\n";
        return cli::kUserError;
    }
    const glare::DebugPass* most = fd.mostError >= 0 ? &fd.passes[size_t(fd.mostError)] : nullptr;
    auto sourceText = [&](const glare::DebugSource& s) {
        std::string t = s.role + " " + s.texture + " " + std::to_string(s.width) + "x" + std::to_string(s.height);
        if (s.role != "target") t += " at (" + num(s.u) + ", " + num(s.v) + ") " + (s.linear ? "linear" : "point");
        t += ":";
        for (const glare::DebugTexel& x : s.texels)
            t += " (" + std::to_string(x.x) + "," + std::to_string(x.y) + ")" +
                 (s.texels.size() > 1 ? "×" + levelText(x.weight) : "");
        t += ", Δ " + levelText(s.levels) + " ← ";
        if (s.from >= 0) {
            const glare::DebugPass& f = fd.passes[size_t(s.from)];
            t += "[" + std::to_string(s.from + 1) + "] " + f.pass;
            if (s.texels.empty() || f.x != s.texels[0].x || f.y != s.texels[0].y)
                t += " (traced at " + std::to_string(f.x) + "," + std::to_string(f.y) + ")";
        } else {
            t += s.origin;
        }
        return t;
    };
    if (json) {
        nlohmann::ordered_json j;
        j["technique"] = fd.technique;
        j["hardware"] = fd.hardware;
        j["size"] = {fd.width, fd.height};
        j["pixel"] = {fd.x, fd.y};
        j["frame"] = fd.frame;
        nlohmann::ordered_json passes = nlohmann::ordered_json::array();
        for (const glare::DebugPass& p : fd.passes) {
            nlohmann::ordered_json o;
            o["pass"] = p.pass;
            o["kind"] = p.kind;
            o["shader"] = p.shader.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(p.shader);
            o["note"] = p.note;
            o["pixel"] = {p.x, p.y};
            o["target"] = {p.width, p.height};
            o["steps"] = debugStepsJson(p.steps, fd.fx);
            o["first_divergence"] = p.firstDivergence >= 0 ? nlohmann::ordered_json(p.steps[size_t(p.firstDivergence)].line)
                                                           : nlohmann::ordered_json(nullptr);
            o["output"] = {{"emulated", p.emulated}, {"ideal", p.ideal}, {"levels", p.levels}};
            o["added"] = p.added;
            if (p.traced) o["traced"] = {{"emulated", p.tracedEmulated}, {"ideal", p.tracedIdeal}};
            nlohmann::ordered_json sources = nlohmann::ordered_json::array();
            for (const glare::DebugSource& s : p.sources) {
                nlohmann::ordered_json so;
                so["role"] = s.role;
                so["texture"] = s.texture;
                so["size"] = {s.width, s.height};
                so["uv"] = {s.u, s.v};
                so["filter"] = s.linear ? "linear" : "point";
                nlohmann::ordered_json texels = nlohmann::ordered_json::array();
                for (const glare::DebugTexel& t : s.texels) texels.push_back({{"x", t.x}, {"y", t.y}, {"weight", t.weight}});
                so["texels"] = texels;
                so["levels"] = s.levels;
                so["from"] = s.from >= 0 ? nlohmann::ordered_json(s.from) : nlohmann::ordered_json(nullptr);
                so["origin"] = s.from >= 0 ? fd.passes[size_t(s.from)].pass : s.origin;
                sources.push_back(so);
            }
            o["sources"] = sources;
            passes.push_back(o);
        }
        j["passes"] = passes;
        j["most_error"] = most ? nlohmann::ordered_json{{"pass", most->pass}, {"levels", most->added}}
                               : nlohmann::ordered_json(nullptr);
        std::cout << j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << "\n";
        return cli::kOk;
    }
    std::printf("%s on %s %ux%u, frame %d: output pixel (%u, %u) followed back through %zu pass(es), %s beside ideal\n",
                fd.technique.c_str(), rq.image ? in.c_str() : ("scene " + rq.scene).c_str(), fd.width, fd.height, fd.frame,
                fd.x, fd.y, fd.passes.size(), fd.hardware.c_str());
    for (size_t k = 0; k < fd.passes.size(); ++k) {
        const glare::DebugPass& p = fd.passes[k];
        std::printf("\n[%zu] %s (%s%s%s), pixel (%u, %u) of %s %ux%u\n", k + 1, p.pass.c_str(), p.kind.c_str(),
                    p.shader.empty() ? "" : " ", p.shader.c_str(), p.x, p.y, p.target.c_str(), p.width, p.height);
        if (!p.note.empty()) std::printf("    %s\n", p.note.c_str());
        std::printf("    output   %-36s ideal %-36s Δ %s levels (%s%s added here)\n", rgba(p.emulated).c_str(),
                    rgba(p.ideal).c_str(), levelText(p.levels).c_str(), p.added >= 0 ? "+" : "", levelText(p.added).c_str());
        for (const glare::DebugSource& s : p.sources) std::printf("    reads    %s\n", sourceText(s).c_str());
        if (p.kind == std::string("device side") || p.kind == std::string("fixed-function"))
            std::printf("    (not a shader pass: the walk ends here)\n");
        if (!p.steps.empty()) printDebugSteps(p.steps, fd.hardware, fd.fx);
    }
    if (most)
        std::printf("\nmost error added by pass %s (%s%s levels)\n", most->pass.c_str(), most->added >= 0 ? "+" : "",
                    levelText(most->added).c_str());
    return cli::kOk;
}

}  // namespace

int debugPixel(const EvalArgs& ea, DebugTrace& out) {
    std::optional<Program> program;
    HardwareConfig hw;
    if (int rc = loadEvalProgram(ea, program, hw); rc != cli::kOk) return rc;
    // ideal on the same class: the same signed decode, no grid, no clamp, float32 filter weights.
    const HardwareConfig ideal = resolveHardware(hw.hardware, program->version.minor, Precision::Ideal, 0);
    std::unique_ptr<Executor> ex = makeEvalExecutor(*program, hw, ea), ei = makeEvalExecutor(*program, ideal, ea);
    if (!ex || !ei) return cli::kUserError;
    TextureSampler sx, si;
    if (int rc = bindEvalTextures(ea, hw, ex->sampledStages(), sx); rc != cli::kOk) return rc;
    {
        std::streambuf* saved = std::cerr.rdbuf(nullptr);  // the notes were printed once
        const int rc = bindEvalTextures(ea, ideal, ei->sampledStages(), si);
        std::cerr.rdbuf(saved);
        if (rc != cli::kOk) return rc;
    }
    const OnePixel px(ea.inputs());
    const Run a = trace(*ex, sx, px), b = trace(*ei, si, px);
    DebugInputs di;
    {
        const ps11test::EvalInputs e = ea.inputs();
        for (size_t c = 0; c < 8; ++c)
            if (ea.constant[c]) di.constants[c] = *ea.constant[c];
        for (size_t v = 0; v < 2; ++v)
            if (e.color[v]) di.color[v] = *e.color[v];
        for (size_t t = 0; t < size_t(kMaxTexCoordSets); ++t)
            if (e.texture[t]) di.texcoord[t] = *e.texture[t];
        // The 1×1 textures: every lookup returns the texel (a stage without one: 0, 0, 0, 1).
        for (int st = 0; st < kMaxTextureStages; ++st) {
            const Texture* tex = sx.texture(st);
            const Vec4 v = tex ? tex->texelValue(0, 0, 0) : Vec4{0, 0, 0, 1};
            for (size_t c = 0; c < 4; ++c) di.stage[size_t(st)][c] = v[c];
        }
    }
    out = DebugTrace{};
    out.shader = ea.shader;
    out.hardware = std::string(hw.hardware->name);
    out.describe = hw.describe();
    out.version = "ps_" + std::to_string(program->version.major) + "_" + std::to_string(program->version.minor);
    out.precision = hw.precision;
    out.rows = debugSteps(*program, hw, di, a.steps, b.steps, sx);
    out.firstDivergence = firstDivergence(out.rows);
    for (size_t c = 0; c < 4; ++c) out.r0Emulated[c] = a.r0[c], out.r0Ideal[c] = b.r0[c];
    out.killedEmulated = a.killed != 0, out.killedIdeal = b.killed != 0;
    return cli::kOk;
}

int cmdDebug(const std::vector<std::string>& argsIn) {
    for (const std::string& a : argsIn)
        if (a == "--technique" || a == "-t") return cmdDebugFrame(argsIn);
    bool json = false;
    std::vector<std::string> args;
    for (const std::string& a : argsIn) (a == "--json" ? json = true : (args.push_back(a), false));
    EvalArgs ea;
    if (int rc = parseEvalArgs(args, "debug", kUsage, ea); rc != cli::kOk) return rc == kHelpShown ? cli::kOk : rc;
    if (ea.precision == Precision::Ideal) {
        std::cerr << "ps11: debug: --precision ideal is the reference it is compared with; pick another profile\n";
        return cli::kUsage;
    }
    DebugTrace d;
    if (int rc = debugPixel(ea, d); rc != cli::kOk) return rc;
    const bool fx = isFixedPoint(d.precision);
    if (json) {
        nlohmann::ordered_json j;
        j["file"] = d.shader;
        j["hardware"] = d.hardware;
        j["precision"] = precisionName(d.precision);
        j["steps"] = debugStepsJson(d.rows, fx);
        j["first_divergence"] = d.firstDivergence >= 0 ? nlohmann::ordered_json(d.rows[size_t(d.firstDivergence)].line)
                                                       : nlohmann::ordered_json(nullptr);
        j["r0"] = {{"emulated", d.r0Emulated}, {"ideal", d.r0Ideal}};
        j["killed"] = {{"emulated", d.killedEmulated}, {"ideal", d.killedIdeal}};
        std::cout << j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << "\n";
        return cli::kOk;
    }
    std::cout << d.shader << ": " << d.version << " on " << d.describe << ", beside ideal\n";
    printDebugSteps(d.rows, d.hardware, fx);
    return cli::kOk;
}

}  // namespace ps11
