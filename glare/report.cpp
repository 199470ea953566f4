#include "glare/report.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include "glare/passes.h"
#include "glare/runner.h"
#include "glare/shade.h"
#include "ps11/assembler.h"
#include "ps11/hardware.h"
#include "ps11/range_proof.h"
#include "ps11/json_internal.h"
#include "ps11/validator.h"

namespace glare {

namespace {

struct ShaderFacts {
    ps11::ShaderStats stats;
    std::string error;
    std::optional<ps11::Program> program;  // when it assembled and validated
};

const ShaderFacts& shaderFacts(const std::string& file) {
    static std::map<std::string, ShaderFacts> cache;
    auto it = cache.find(file);
    if (it != cache.end()) return it->second;
    ShaderFacts facts;
    const std::string_view* text = shaderText(file);
    if (!text) {
        facts.error = "no such shader";
    } else {
        ps11::Diagnostics diags;
        std::optional<ps11::Program> p = ps11::parseAssembly(*text, "glare/shaders/" + file, {}, diags);
        if (p) ps11::validate(*p, diags, &facts.stats);
        if (!p || diags.hasErrors())
            facts.error = diags.formatAll();
        else
            facts.program = std::move(p);
    }
    return cache.emplace(file, std::move(facts)).first->second;
}

// The range proof of one shader pass on `hardware` with the constants the pass sets, its
// textures 8-bit ([0, 1]) and filtered as its taps are: empty when no register clamp acts, else
// "line N: instruction".
std::string rangeClamp(const ps11::Program& program, const PassInfo& info, const ps11::HardwareConfig& hardware) {
    ps11::RangeProofSetup setup;
    setup.options = ps11::executorOptionsFor(hardware);
    for (const auto& [index, value] : info.constants)
        if (index >= 0 && index < 8) setup.constants[size_t(index)] = value;
    for (int stage = 0; stage < ps11::kMaxTextureStages; ++stage)
        setup.filtered[size_t(stage)] = !((info.pointStages >> stage) & 1);
    ps11::Diagnostics diags;
    const std::optional<ps11::RangeProof> proof = ps11::proveRanges(program, setup, diags);
    if (!proof) return "not analysed: " + diags.formatAll();
    const ps11::InstructionRange* first = proof->firstClamp();
    return first ? "line " + std::to_string(first->loc.line) + ": `" + first->text + "`" : std::string();
}

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

}  // namespace

FitsReport fitsReport(uint32_t width, uint32_t height) {
    FitsReport r;
    r.width = width;
    r.height = height;
    RunnerOptions ro;
    ro.width = width;
    ro.height = height;
    Runner runner(ro);
    r.hardware = runner.device().hardware().hardware->name;
    for (const Technique* t : techniques())
        for (size_t p = 0; p < kPresetNames.size(); ++p) {
            const Settings s = *presetSettings(*t, kPresetNames[p]);
            PassGraph g;
            runner.buildFrame(*t, s, 1, 2, g);  // frame 1: the steady state (blending on)
            for (const PassGraph::PassNode& n : g.passes()) {
                if (!n.live) continue;
                PassFit f;
                f.technique = std::string(t->name());
                f.preset = std::string(kPresetNames[p]);
                f.pass = n.info.name;
                f.kind = n.info.kind;
                f.shader = n.info.shader;
                f.note = n.info.note;
                for (TextureId w : n.writes)
                    if (!g.texture(w).data) {
                        f.width = g.texture(w).desc.width;
                        f.height = g.texture(w).desc.height;
                    }
                if (n.info.kind == PassKind::Shader) {
                    const ShaderFacts& facts = shaderFacts(n.info.shader);
                    const ps11::ShaderStats& st = facts.stats;
                    f.version = "ps_1_" + std::to_string(st.version.minor);
                    f.texSlots = st.texSlots;
                    f.texLimit = st.texLimit;
                    f.arithSlots = st.arithSlots;
                    f.arithLimit = st.arithLimit;
                    f.constants = st.constantsRead;
                    f.fits = facts.error.empty() && st.valid && st.version.minor == 1 && st.texSlots <= st.texLimit &&
                             st.arithSlots <= st.arithLimit;
                    if (!facts.error.empty()) f.note = facts.error;
                    if (facts.program) f.rangeClamp = rangeClamp(*facts.program, n.info, runner.device().hardware());
                } else if (n.info.kind == PassKind::DeviceSide) {
                    // The glare image is computed on the CPU and uploaded, as the paper's precomputed image:
                    // a texture upload, which 1.1-class hardware takes. The sensors are the step past 1.1.
                    f.fits = n.info.name == "glare_image";
                    f.width = f.height = 0;
                }
                r.passes.push_back(f);
            }
        }
    return r;
}

std::string fitsReportJson(const FitsReport& r) {
    using ps11::json::Json;
    Json passes = Json::array();
    for (const PassFit& f : r.passes)
        passes.push_back({{"technique", f.technique},
                          {"preset", f.preset},
                          {"pass", f.pass},
                          {"kind", passKindName(f.kind)},
                          {"shader", f.shader},
                          {"version", f.version},
                          {"tex_slots", f.texSlots},
                          {"tex_limit", f.texLimit},
                          {"arith_slots", f.arithSlots},
                          {"arith_limit", f.arithLimit},
                          {"constants", f.constants},
                          {"target", {f.width, f.height}},
                          {"fits_ps_1_1", f.fits},
                          {"range_safe", f.rangeClamp.empty()},
                          {"range_clamp", f.rangeClamp},
                          {"note", f.note}});
    Json j;
    j["frame"] = {r.width, r.height};
    j["hardware"] = r.hardware;
    j["passes"] = std::move(passes);
    // One pass per line, as before.
    return ps11::json::dump(j, 2) + "\n";
}

namespace {

// b·min(4b, 1) against 4b²: the adaptive bright pass on single colours, fx8 and ideal.
std::string brightPassTable() {
    const float cs[] = {0.45f, 0.50f, 0.55f, 0.60f, 0.65f, 0.70f, 0.80f, 1.00f};
    ShadeRequest q;
    q.shaderText = std::string(*shaderText("adaptive_bright.psh"));
    ShadeTexture scene, amount;
    scene.image = {uint32_t(std::size(cs)), 1, {}};
    for (float c : cs) scene.image.rgba.insert(scene.image.rgba.end(), {c, c, c, 1});
    scene.filter = D3DTEXF_POINT;
    amount.image = {1, 1, {0, 0, 0, 1}};
    amount.filter = D3DTEXF_POINT;
    q.textures = {scene, amount};
    q.constants = {{0, {0.4f, 0.4f, 0.4f, 0}}, {1, {1, 1, 1, 1}}};
    std::string out = "| scene c | b = c − 0.4 | intended 4b² | ideal | fx8 (geforce4) | fx8 − ideal (levels) |\n"
                      "|---|---|---|---|---|---|\n";
    std::string err;
    emu::DeviceOptions fx, ideal;
    ideal.precision = ps11::Precision::Ideal;
    const auto a = shade(fx, q, err), b = shade(ideal, q, err);
    if (!a || !b) return "(could not compute: " + err + ")\n";
    for (size_t i = 0; i < std::size(cs); ++i) {
        const double bb = double(cs[i]) - 0.4;
        const double f8 = a->rgba[i * 4], id = b->rgba[i * 4];
        out += "| " + fmt("%.2f", cs[i]) + " | " + fmt("%.2f", bb) + " | " + fmt("%.4f", 4 * bb * bb) + " | " +
               fmt("%.4f", id) + " | " + fmt("%.4f", f8) + " | " + fmt("%+.0f", std::round((f8 - id) * 255)) + " |\n";
    }
    return out;
}

// The adapted glare amount after n frames from black towards a uniform grey scene, fx8 and ideal.
std::string smoothingTable() {
    const uint32_t size = 16;
    const float grey = 0.5f;
    std::string out = "| frames | ideal A | fx8 A | fx8 − ideal (levels) |\n|---|---|---|---|\n";
    std::vector<std::pair<int, std::array<double, 2>>> rows;
    const int marks[] = {1, 10, 30, 100, 200, 400};
    std::array<std::vector<double>, 2> series;
    for (int p = 0; p < 2; ++p) {
        RunnerOptions ro;
        ro.width = ro.height = size;
        if (p == 1) ro.device.precision = ps11::Precision::Ideal;
        Runner run(ro);
        std::string err;
        emu::FloatImage img{size, size, std::vector<float>(size_t(size) * size * 4, grey)};
        if (!run.setImage(img, err)) return "(could not compute: " + err + ")\n";
        Settings s = *presetSettings(*findTechnique("adaptive"), "published");
        s["start"] = 1;  // black
        for (int f = 0; f < 400; ++f) {
            FrameResult fr;
            if (!run.runFrame(*findTechnique("adaptive"), s, f, 400, fr, err)) return "(could not compute: " + err + ")\n";
            const emu::Handle h = run.persistent("adapted glare amount", {1, 1, run.intermediateFormat()}, 0, err);
            std::optional<emu::RgbaImage> px;
            if (p == 0) {
                px = run.readTexture(h, err);
                if (!px) return "(could not compute: " + err + ")\n";
                series[0].push_back(px->rgba[0] / 255.0);
            } else {
                // Float: read the value itself, not its 8-bit picture.
                emu::Handle surface{};
                run.device().GetSurfaceLevel(h, 0, &surface);
                std::optional<emu::SurfacePixels> sp = emu::readSurface(run.device(), surface, err);
                if (!sp) return "(could not compute: " + err + ")\n";
                float v;
                std::memcpy(&v, sp->bytes.data(), 4);
                series[1].push_back(v);
            }
        }
    }
    for (int m : marks) {
        const double f8 = series[0][size_t(m - 1)], id = series[1][size_t(m - 1)];
        out += "| " + std::to_string(m) + " | " + fmt("%.4f", id) + " | " + fmt("%.4f", f8) + " | " +
               fmt("%+.1f", (f8 - id) * 255) + " |\n";
    }
    return out;
}

// Every technique on its scene, published settings, the default 1.1-class card against ideal.
std::string accuracyTable(uint32_t w, uint32_t h) {
    std::string out = "| technique | scene | max | mean | pixels > 1 level |\n|---|---|---|---|---|\n";
    for (const Technique* t : techniques()) {
        RunnerOptions ro;
        ro.width = w;
        ro.height = h;
        std::string err;
        const SceneRun fx = runOnScene(*t, ro, 1, err);
        ro.device.precision = ps11::Precision::Ideal;
        const SceneRun ideal = fx.image ? runOnScene(*t, ro, 1, err) : SceneRun{};
        if (!fx.image || !ideal.image) return "(could not compute: " + err + ")\n";
        const ImageError e = imageError(*fx.image, *ideal.image);
        out += "| " + std::string(t->name()) + " | " + std::string(t->scene()) + " | " + std::to_string(e.max) + " | " +
               fmt("%.3f", e.mean) + " | " + fmt("%.2f %%", e.overOnePercent) + " |\n";
    }
    return out;
}

std::string diffusedExample() {
    const std::vector<double> q = quantiseWeights({5.0 / 16, 6.0 / 16, 5.0 / 16}, ps11::Precision::Fx8);
    std::string out;
    double sum = 0;
    for (double w : q) {
        out += (out.empty() ? "" : ", ") + fmt("%.0f", w * 255);
        sum += w;
    }
    return out + " /255, Σ = " + fmt("%.0f", sum * 255) + "/255";
}

}  // namespace

std::string fitsReportMarkdown(const FitsReport& r) {
    std::string md =
        "# Fits ps_1_1: the proof\n\n"
        "Generated by `ps11 glare --report --markdown` (do not edit: `tests/cli/cli_test.sh` checks that this file is "
        "current). Every pass of every technique and preset (`low`, `medium`, `high`, `published`), built for a " +
        std::to_string(r.width) + "x" + std::to_string(r.height) +
        " frame; every shader assembled from `glare/shaders/` and validated against the limits of ps_1_1 (4 texture "
        "and 8 arithmetic slots, c0–c7, 2 read ports per register type) as the default 1.1-class card (`" +
        r.hardware +
        "`) runs it. StretchRect, Clear and fixed-function texture stages are what 1.1-class hardware does without a "
        "shader. A step marked **no** needs more than 1.1, and the table says why. **range-safe** is the other limit "
        "of the hardware, the value range: the range proof of `ps11 check --ranges` (docs/intervals.md) on the card, "
        "with the constants the pass sets and its textures in [0, 1]: `yes` when no register clamp to ±MaxValue can act, "
        "else the first instruction whose result can pass it (a finding, not an error: Sousa's `mov_x4` is meant to "
        "clamp).\n\n";
    // One table per technique: the passes of the published preset, then what the other presets change.
    for (const Technique* t : techniques()) {
        md += "## " + std::string(t->title()) + " (`" + std::string(t->name()) + "`)\n\n";
        for (size_t p = 0; p < kPresetNames.size(); ++p) {
            const std::string preset(kPresetNames[p]);
            md += "### preset `" + preset + "`: ";
            const Settings s = *presetSettings(*t, preset);
            std::string settings;
            for (const ParamInfo& pi : t->params()) settings += (settings.empty() ? "" : ", ") + pi.name + "=" + settingText(pi, s.at(pi.name));
            md += settings + "\n\n| pass | kind | shader | version | tex slots | arith slots | constants | target | fits 1.1 | "
                             "range-safe |\n|---|---|---|---|---|---|---|---|---|---|\n";
            int total = 0, fitting = 0;
            for (const PassFit& f : r.passes) {
                if (f.technique != t->name() || f.preset != preset) continue;
                ++total;
                fitting += f.fits;
                std::string consts;
                for (int c : f.constants) consts += (consts.empty() ? "c" : " c") + std::to_string(c);
                const bool shader = f.kind == PassKind::Shader;
                md += "| " + f.pass + " | " + passKindName(f.kind) + " | " + (shader ? "`" + f.shader + "`" : "—") + " | " +
                      (shader ? f.version : "—") + " | " +
                      (shader ? std::to_string(f.texSlots) + "/" + std::to_string(f.texLimit) : "—") + " | " +
                      (shader ? std::to_string(f.arithSlots) + "/" + std::to_string(f.arithLimit) : "—") + " | " +
                      (consts.empty() ? "—" : consts) + " | " +
                      (f.width ? std::to_string(f.width) + "x" + std::to_string(f.height) : "CPU") + " | " +
                      (f.fits ? "yes" : "**no**: " + f.note) + " | " +
                      (!shader ? "—" : f.rangeClamp.empty() ? "yes" : "clamps at " + f.rangeClamp) + " |\n";
            }
            md += "\n" + std::to_string(fitting) + " of " + std::to_string(total) + " passes fit ps_1_1.\n\n";
        }
    }
    md += "## Where ps_1_1 changes the result\n\n"
          "### Each technique, fx8 against ideal\n\n"
          "The published settings on each technique's own scene (its first frame, 480x270), run on the default "
          "1.1-class card (fx8, MaxValue 1, 8-bit render targets) and under `ideal` (float, no clamping but `_sat` and "
          "the output, float render targets); the difference of the two outputs in 8-bit levels over RGB. `ps11 demo` "
          "prints the same at its own size.\n\n" +
          accuracyTable(480, 270) +
          "\n"
          "### `4·b²` in Sousa's bright pass\n\n"
          "`4·b²` compiles to `mov_x4 r1, r0` then `mul r0, r0, r1`. A 1.1-class card clamps registers to [−1, 1] "
          "(PixelShader1xMaxValue = 1), so `mov_x4` gives min(4b, 1) and the pass computes b·min(4b, 1): equal to 4b² "
          "only for b ≤ 0.25. The `ideal` profile keeps 4b² (then saturates at the output). Computed by running "
          "`adaptive_bright.psh` on one pixel per colour (A = 0), fx8 on the default class against ideal:\n\n" +
          brightPassTable() +
          "\n### 8-bit temporal smoothing\n\n"
          "The adapted glare amount is `A ← Q(0.025·L + 0.975·A)` in an 8-bit 1x1 target. With round-to-nearest the "
          "step 0.025·(L − A) vanishes once it is below half a level, so A stops about 0.5/0.025 = 20 levels short of "
          "its target (GLARE.md §7). Computed with the whole `adaptive` technique (published preset, `start=black`) on "
          "a uniform grey 0.5 scene, whose target is 4·0.5² = 1 before the luminance weights, A → 1.0:\n\n" +
          smoothingTable() +
          "\n### Kernel weights on the 8-bit grid\n\n"
          "Constants of the fx profiles sit on the 1/255 grid. Rounding each weight of a normalised kernel on its own "
          "gives Σw ≠ 1 (the pyramid's 5/16, 6/16, 5/16 become 80, 96, 80 /255: Σ = 256/255 = 1.0039); the techniques "
          "quantise with error diffusion (`glare/passes.h` `quantiseWeights`: each remainder carried into the next "
          "weight), so the quantised weights of every pass sum to the quantised sum exactly: for the pyramid " +
          diffusedExample() + " (`tests/test_glare.cpp` checks the sums of every kernel).\n";
    return md;
}

}  // namespace glare
