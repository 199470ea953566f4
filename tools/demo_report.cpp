// `ps11 demo`'s report (tools/demo_report.h): gathers every section's numbers and images from
// the libraries (glare/runner, glare/compare, glare/report, glare/sweep, glare/stress, the
// executor's trace) and writes one HTML page with SVG plots (tools/svg_plot.h) and PNGs beside it.
#include "tools/demo_report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>
#include <tuple>
#include <vector>

#include "emu/image_file.h"
#include "glare/compare.h"
#include "glare/photos.h"
#include "glare/report.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "glare/stress.h"
#include "glare/sweep.h"
#include "ps11/version.h"
#include "tools/cli_util.h"
#include "tools/cmd_debug.h"
#include "runner/gl_backend.h"
#include "tools/svg_plot.h"

namespace ps11 {
namespace {

using Clock = std::chrono::steady_clock;

// Progress on stderr: "[ 12.3 s] section: what".
class Progress {
public:
    void operator()(const std::string& what) const {
        const double s = std::chrono::duration<double>(Clock::now() - m_start).count();
        std::fprintf(stderr, "[%6.1f s] %s\n", s, what.c_str());
    }
    double seconds() const { return std::chrono::duration<double>(Clock::now() - m_start).count(); }

private:
    Clock::time_point m_start = Clock::now();
};

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

std::string safeName(const std::string& s) {
    std::string out;
    for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '_';
    return out;
}

// |a − b| over RGB as a heat map: black where equal, then red to yellow with the difference
// (1 level is clearly visible, 8 and more is yellow).
emu::RgbaImage heatMap(const emu::RgbaImage& a, const emu::RgbaImage& b) {
    emu::RgbaImage h{a.width, a.height, std::vector<uint8_t>(a.rgba.size(), 0)};
    for (size_t i = 0; i + 3 < a.rgba.size() && i + 3 < b.rgba.size(); i += 4) {
        int d = 0;
        for (size_t c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a.rgba[i + c]) - int(b.rgba[i + c])));
        const double t = d == 0 ? 0 : std::min(1.0, 0.35 + 0.65 * std::log2(1.0 + d) / 3.0);
        h.rgba[i] = uint8_t(d ? 255 * std::min(1.0, t * 1.6) : 0);
        h.rgba[i + 1] = uint8_t(d ? 255 * std::max(0.0, t * 1.6 - 0.6) : 0);
        h.rgba[i + 3] = 255;
    }
    return h;
}

struct Ctx {
    const DemoReportOptions& o;
    std::string dir;
    Progress progress;
    ps11test::RendererFactory glNative, glExact;
    std::string glDescription, glMissing;
    const HardwareClass* cls = nullptr;
    std::string error;

    bool png(const std::string& rel, const emu::RgbaImage& img) {
        return emu::writePng(dir + "/" + rel, img, error);
    }
    glare::RunnerOptions runnerOptions(uint32_t w, uint32_t h) const {
        glare::RunnerOptions ro;
        ro.width = w;
        ro.height = h;
        ro.device.hardware = cls;
        ro.device.software.threads = o.threads;
        return ro;
    }
};

// ---- the techniques ------------------------------------------------------------------------

struct PassImage {
    std::string pass, texture, file;
};

struct TechniqueShow {
    const glare::Technique* t = nullptr;
    std::string input, emulated, ideal, glNative, heat;  // files, relative to the report
    glare::ImageError emuError, glError;
    bool hasGl = false;
    std::vector<PassImage> passes;
    std::vector<glare::PassAgreement> agreement;
};

bool showTechnique(Ctx& c, const glare::Technique& t, uint32_t w, uint32_t h, TechniqueShow& show) {
    show.t = &t;
    const std::string name(t.name());
    const glare::Settings settings = *glare::presetSettings(t, "published");
    std::string& err = c.error;
    glare::Runner emu(c.runnerOptions(w, h));
    std::unique_ptr<glare::Scene> scene = glare::makeScene(t.scene(), err);
    if (!scene) return false;
    const auto [fogStart, fogEnd] = t.sceneGlowFog(settings);
    scene->setGlowFog(fogStart, fogEnd);
    double ms = 0;
    if (!emu.renderScene(*scene, 0, 8, ms, err)) return false;
    std::optional<emu::RgbaImage> input = emu.readTexture(emu.sceneTexture(), err);
    if (!input) return false;
    show.input = "img/" + name + "-input.png";
    if (!c.png(show.input, emu::opaque(*input))) return false;

    // The emulated frame, pass-isolated against GL's exact mode where there is GL, with every
    // pass's output kept for the contact sheet.
    auto dump = [&](glare::PassGraph& g, uint32_t pass, bool after, std::string& e) {
        if (!after) return true;
        const glare::PassGraph::PassNode& n = g.passes()[pass];
        c.progress("techniques: " + name + ": " + n.info.name);
        for (glare::TextureId id : n.writes) {
            if (g.texture(id).data) continue;
            std::optional<emu::RgbaImage> img = emu.readTexture(g.texture(id).device, e);
            if (!img) return false;
            char prefix[8];
            std::snprintf(prefix, sizeof prefix, "%02u", pass);
            PassImage pi{n.info.name, g.texture(id).name,
                         "img/" + name + "-pass" + prefix + "-" + safeName(n.info.name) + ".png"};
            if (!emu::writePng(c.dir + "/" + pi.file, emu::opaque(*img), e)) return false;
            show.passes.push_back(pi);
        }
        return true;
    };
    glare::FrameResult result;
    std::unique_ptr<glare::Runner> exact;
    if (c.glExact) {
        glare::RunnerOptions ro = c.runnerOptions(w, h);
        ro.device.renderer = c.glExact;
        exact = std::make_unique<glare::Runner>(ro);
        if (!exact->setImage(*input, err) ||
            !glare::compareFrame(emu, *exact, t, settings, 0, 1, show.agreement, result, err, dump))
            return false;
    } else {
        glare::PassGraph* built = nullptr;
        if (!emu.runFrame(
                t, settings, 0, 1, result, err,
                [&](uint32_t pass, bool after, std::string& e) { return dump(*built, pass, after, e); },
                [&](glare::PassGraph& g) { built = &g; }, true))
            return false;
    }
    std::optional<emu::RgbaImage> out = emu.readOutput(err);
    if (!out) return false;
    *out = emu::opaque(*out);
    show.emulated = "img/" + name + "-emulated.png";
    if (!c.png(show.emulated, *out)) return false;
    if (exact) {
        std::optional<emu::RgbaImage> gx = exact->readOutput(err);
        if (!gx) return false;
        bool differs = false;
        for (const glare::PassAgreement& a : show.agreement) differs = differs || a.exact < a.pixels;
        if (differs) {
            show.heat = "img/" + name + "-heat.png";
            if (!c.png(show.heat, heatMap(*out, emu::opaque(*gx)))) return false;
        }
    }

    // ideal and GL native on the same input.
    glare::RunnerOptions io = c.runnerOptions(w, h);
    io.device.precision = Precision::Ideal;
    glare::Runner ideal(io);
    glare::FrameResult r;
    std::optional<emu::RgbaImage> idealOut;
    if (!ideal.setImage(*input, err) || !ideal.runFrame(t, settings, 0, 1, r, err) || !(idealOut = ideal.readOutput(err)))
        return false;
    *idealOut = emu::opaque(*idealOut);
    show.ideal = "img/" + name + "-ideal.png";
    if (!c.png(show.ideal, *idealOut)) return false;
    show.emuError = glare::imageError(*out, *idealOut);
    if (c.glNative) {
        glare::RunnerOptions no = c.runnerOptions(w, h);
        no.device.renderer = c.glNative;
        glare::Runner native(no);
        std::optional<emu::RgbaImage> gn;
        if (!native.setImage(*input, err) || !native.runFrame(t, settings, 0, 1, r, err) || !(gn = native.readOutput(err)))
            return false;
        *gn = emu::opaque(*gn);
        show.glNative = "img/" + name + "-gl-native.png";
        if (!c.png(show.glNative, *gn)) return false;
        show.glError = glare::imageError(*gn, *idealOut);
        show.hasGl = true;
    }
    return true;
}

std::string figure(const std::string& file, const std::string& caption, int width = 300) {
    if (file.empty()) return "";
    return "<figure><a href=\"" + htmlEscape(file) + "\"><img src=\"" + htmlEscape(file) + "\" width=\"" +
           std::to_string(width) + "\" alt=\"" + htmlEscape(caption) + "\"></a><figcaption>" + caption +
           "</figcaption></figure>";
}

std::string errorText(const glare::ImageError& e) {
    return "max " + std::to_string(e.max) + ", mean " + fmt("%.3f", e.mean) + " levels, " + fmt("%.2f", e.overOnePercent) +
           " % of pixels &gt; 1";
}

std::string techniquesSection(const Ctx& c, const std::vector<TechniqueShow>& shows, uint32_t w, uint32_t h) {
    std::string s = "<section id=\"techniques\"><h2>The five techniques</h2>\n<p>Each on its built-in scene at " +
                    std::to_string(w) + "×" + std::to_string(h) +
                    ", published settings, frame 0: the input, the emulated " + htmlEscape(std::string(c.cls->name)) +
                    " running the real ps_1_1 passes, <code>ideal</code> (float, no clamping: the reference every "
                    "error is measured against) and the same technique on the GL renderer's native mode (plain GLSL, "
                    "the speed peer). Errors are against ideal over RGB in 8-bit levels. Click an image to enlarge "
                    "it.</p>\n";
    for (const TechniqueShow& t : shows) {
        s += "<h3>" + htmlEscape(std::string(t.t->title())) + " <small>(<code>" + htmlEscape(std::string(t.t->name())) +
             "</code>, scene <code>" + htmlEscape(std::string(t.t->scene())) + "</code>)</small></h3>\n<div class=\"row\">";
        s += figure(t.input, "input");
        s += figure(t.emulated, "emulated " + htmlEscape(std::string(c.cls->name)) + ": " + errorText(t.emuError));
        s += figure(t.ideal, "ideal");
        if (t.hasGl) s += figure(t.glNative, "GL native: " + errorText(t.glError));
        s += "</div>\n<details><summary>contact sheet: every pass (" + std::to_string(t.passes.size()) +
             " outputs)</summary><div class=\"sheet\">";
        for (const PassImage& p : t.passes) s += figure(p.file, htmlEscape(p.pass + " → " + p.texture), 150);
        s += "</div></details>\n";
    }
    return s + "</section>\n";
}

std::string agreementSection(const Ctx& c, const std::vector<TechniqueShow>& shows) {
    std::string s = "<section id=\"agreement\"><h2>The emulator against the GL renderer</h2>\n";
    if (!c.glExact) return s + "<p>No OpenGL context on this machine (" + htmlEscape(c.glMissing) + ").</p></section>\n";
    s += "<p>Every pass of every technique run twice, pass-isolated: on the emulator and on the GL renderer's exact "
         "mode (" + htmlEscape(c.glDescription) +
         "), each GL pass fed exactly the inputs the emulator's pass had, so an early difference can neither hide nor "
         "grow later. Compared in 8-bit levels.</p>\n<table><tr><th>technique</th><th>pass</th><th>pixels</th><th>% "
         "exact</th><th>max |Δ|</th></tr>\n";
    for (const TechniqueShow& t : shows)
        for (const glare::PassAgreement& a : t.agreement)
            s += "<tr><td>" + htmlEscape(std::string(t.t->name())) + "</td><td>" + htmlEscape(a.pass) + "</td><td>" +
                 std::to_string(a.pixels) + "</td><td>" +
                 fmt("%.4f", a.pixels ? 100.0 * double(a.exact) / double(a.pixels) : 100.0) + "</td><td" +
                 (a.maxDiff > 0 ? " class=\"bad\"" : "") + ">" + fmt("%.0f", a.maxDiff) + "</td></tr>\n";
    s += "</table>\n";
    bool any = false;
    for (const TechniqueShow& t : shows)
        if (!t.heat.empty()) {
            s += figure(t.heat, htmlEscape(std::string(t.t->name())) + ": where the final outputs differ");
            any = true;
        }
    if (!any) s += "<p>Every pass of every technique is bit for bit the same on both renderers: no heat map to show.</p>\n";
    return s + "</section>\n";
}

// ---- real photographs -------------------------------------------------------------------------

struct PhotoShow {
    glare::Photo photo;
    std::string input;
    std::vector<std::tuple<std::string, std::string, std::string, glare::ImageError>> results;  // technique, emu, gl, |emu − gl|
};

// The sample photographs (tools/sample-images.sh) the report shows: the flame, the city at dusk
// and the night sky first, the first `count` of them present.
std::vector<glare::Photo> pickPhotos(const std::vector<glare::Photo>& all, size_t count) {
    std::vector<glare::Photo> out;
    for (const char* want : {"CandleGlass", "GoldenGate", "night", "Desk", "StillLife", "sunset"})
        for (const glare::Photo& p : all)
            if (out.size() < count && p.name.find(want) != std::string::npos) out.push_back(p);
    return out;
}

bool showPhoto(Ctx& c, const glare::Photo& photo, PhotoShow& show) {
    std::string& err = c.error;
    std::optional<emu::LoadedImage> loaded = emu::readImage(photo.path, err);
    if (!loaded) return false;
    const emu::FloatImage image = loaded->hdr ? emu::exposeUnclamped(loaded->image, 0) : loaded->image;
    show.photo = photo;
    const std::string stem = safeName(std::filesystem::path(photo.name).stem().string());
    for (const glare::Technique* t : glare::techniques()) {
        c.progress("photographs: " + photo.name + ": " + std::string(t->name()));
        const glare::Settings settings = *glare::presetSettings(*t, "published");
        glare::Runner emu(c.runnerOptions(image.width, image.height));
        glare::FrameResult r;
        std::optional<emu::RgbaImage> out;
        if (!emu.setImage(image, err) || !emu.runFrame(*t, settings, 0, 1, r, err) || !(out = emu.readOutput(err)))
            return false;
        if (show.input.empty()) {
            std::optional<emu::RgbaImage> in = emu.readTexture(emu.sceneTexture(), err);
            if (!in) return false;
            show.input = "img/photo-" + stem + "-input.png";
            if (!c.png(show.input, emu::opaque(*in))) return false;
        }
        const std::string name(t->name());
        std::string emuFile = "img/photo-" + stem + "-" + name + "-emulated.png", glFile;
        if (!c.png(emuFile, emu::opaque(*out))) return false;
        glare::ImageError e;
        if (c.glNative) {
            glare::RunnerOptions no = c.runnerOptions(image.width, image.height);
            no.device.renderer = c.glNative;
            glare::Runner native(no);
            std::optional<emu::RgbaImage> g;
            if (!native.setImage(image, err) || !native.runFrame(*t, settings, 0, 1, r, err) || !(g = native.readOutput(err)))
                return false;
            glFile = "img/photo-" + stem + "-" + name + "-gl-native.png";
            if (!c.png(glFile, emu::opaque(*g))) return false;
            e = glare::imageError(emu::opaque(*out), emu::opaque(*g));
        }
        show.results.emplace_back(name, emuFile, glFile, e);
    }
    return true;
}

std::string photosSection(const std::vector<PhotoShow>& shows, const std::string& missing) {
    std::string s = "<section id=\"photos\"><h2>Real photographs</h2>\n";
    if (shows.empty())
        return s + "<p>No sample photographs here: " + htmlEscape(missing) + "</p></section>\n";
    s += "<p>HDR photographs from Debian packages (fetched by <code>tools/sample-images.sh</code>, never part of "
         "the repository), exposure 0, published settings: each technique on the emulated card and on the GL "
         "renderer's native mode, with their difference in 8-bit levels.</p>\n";
    for (const PhotoShow& p : shows) {
        s += "<h3>" + htmlEscape(p.photo.name) + "</h3>\n<p><small>" + htmlEscape(p.photo.description) + "; licence " +
             htmlEscape(p.photo.licence) + ", from the Debian package " + htmlEscape(p.photo.package) +
             "</small></p>\n<div class=\"row\">" + figure(p.input, "input (the 8-bit scene the card sees)", 240);
        for (const auto& [name, emuFile, glFile, e] : p.results) {
            s += figure(emuFile, htmlEscape(name) + ", emulated", 240);
            if (!glFile.empty())
                s += figure(glFile, htmlEscape(name) + ", GL native: against the card max " + std::to_string(e.max) +
                                        ", mean " + fmt("%.3f", e.mean),
                            240);
        }
        s += "</div>\n";
    }
    return s + "</section>\n";
}

// ---- fits ----------------------------------------------------------------------------------

std::string fitsSection(const glare::FitsReport& r) {
    std::string s = "<section id=\"fits\"><h2>Fits ps_1_1</h2>\n<p>Every pass of the published settings at " +
                    std::to_string(r.width) + "×" + std::to_string(r.height) +
                    ", each shader validated against the limits of ps_1_1 on <code>" + htmlEscape(r.hardware) +
                    "</code> (4 texture and 8 arithmetic slots, c0–c7), and its value range proven with the constants "
                    "the pass sets (<code>ps11 check --ranges</code>): <em>range-safe</em> when no register clamp to "
                    "±MaxValue can act, else the first instruction whose result can pass it. Every preset: "
                    "<code>docs/fits-ps11.md</code>.</p>\n<table><tr><th>technique</th><th>pass</th><th>kind</th><th>"
                    "shader</th><th>tex</th><th>arith</th><th>constants</th><th>target</th><th>fits 1.1</th><th>"
                    "range-safe</th></tr>\n";
    for (const glare::PassFit& f : r.passes) {
        if (f.preset != "published") continue;
        const bool shader = f.kind == glare::PassKind::Shader;
        std::string consts;
        for (int k : f.constants) consts += (consts.empty() ? "c" : " c") + std::to_string(k);
        s += "<tr><td>" + htmlEscape(f.technique) + "</td><td>" + htmlEscape(f.pass) + "</td><td>" +
             htmlEscape(glare::passKindName(f.kind)) + "</td><td>" + (shader ? "<code>" + htmlEscape(f.shader) + "</code>" : "—") +
             "</td><td>" + (shader ? std::to_string(f.texSlots) + "/" + std::to_string(f.texLimit) : "—") + "</td><td>" +
             (shader ? std::to_string(f.arithSlots) + "/" + std::to_string(f.arithLimit) : "—") + "</td><td>" +
             (consts.empty() ? "—" : consts) + "</td><td>" +
             (f.width ? std::to_string(f.width) + "×" + std::to_string(f.height) : "CPU") + "</td><td" +
             (f.fits ? ">yes" : " class=\"bad\">no: " + htmlEscape(f.note)) + "</td><td>" +
             (!shader ? "—" : f.rangeClamp.empty() ? "yes" : "clamps at " + htmlEscape(f.rangeClamp)) + "</td></tr>\n";
    }
    return s + "</table></section>\n";
}

// ---- run time against error ------------------------------------------------------------------

std::string benchSection(const Ctx& c, const std::vector<glare::SweepRow>& rows, const glare::SweepSpec& spec) {
    std::string s = "<section id=\"bench\"><h2>Run time against error</h2>\n<p><code>ps11 bench</code>'s sweep: every "
                    "technique at " + std::to_string(spec.width) + "×" + std::to_string(spec.height) + ", presets ";
    for (size_t i = 0; i < spec.qualities.size(); ++i) s += (i ? ", " : "") + spec.qualities[i];
    s += ", on the emulator (" + htmlEscape(std::string(c.cls->name)) + ")" +
         (c.glNative ? " and on the GL renderer's native mode (" + htmlEscape(c.glDescription) + ")" : std::string()) +
         "; the median of " + std::to_string(spec.frames) + " warm frames (" +
         std::to_string(std::thread::hardware_concurrency()) +
         " hardware threads here), measured in one run, interleaved. Error: the mean |Δ| in 8-bit levels of the "
         "output against the technique's ideal reference. Filled points are the Pareto front: no other row is both "
         "faster and more accurate.</p>\n<div class=\"row\">";
    for (const glare::Technique* t : glare::techniques()) {
        std::vector<PlotPoint> pts;
        for (const glare::SweepRow& r : rows)
            if (r.technique == t->name())
                pts.push_back({r.msMedian, r.error.mean, r.quality + " " + (r.backend == "gl" ? "GL" : "emu"), r.pareto});
        PlotAxes ax;
        ax.title = std::string(t->name());
        ax.xLabel = "ms per frame (median)";
        ax.yLabel = "mean |Δ| vs ideal (levels)";
        ax.width = 420;
        ax.height = 260;
        s += "<div class=\"plot\">" + svgScatter(ax, pts) + "</div>";
    }
    s += "</div>\n<h3>Speed against the GL renderer's native mode (published)</h3>\n<table><tr><th>technique</th><th>"
         "emulator ms</th><th>GL native ms</th><th>emulator / GL speed</th><th>emulator error</th><th>GL native "
         "error</th></tr>\n";
    for (const glare::Technique* t : glare::techniques()) {
        const glare::SweepRow *e = nullptr, *g = nullptr;
        for (const glare::SweepRow& r : rows)
            if (r.technique == t->name() && r.quality == "published") (r.backend == "gl" ? g : e) = &r;
        if (!e) continue;
        s += "<tr><td>" + htmlEscape(std::string(t->name())) + "</td><td>" + fmt("%.2f", e->msMedian) + "</td><td>" +
             (g ? fmt("%.2f", g->msMedian) : "—") + "</td><td>" + (g ? fmt("%.2f×", g->msMedian / e->msMedian) : "—") +
             "</td><td>" + fmt("%.3f", e->error.mean) + "</td><td>" + (g ? fmt("%.3f", g->error.mean) : "—") +
             "</td></tr>\n";
    }
    return s + "</table>\n<p>A ratio above 1 means the emulator's real ps_1_1 passes are faster than the same technique "
               "as plain GLSL on this GL renderer.</p></section>\n";
}

// ---- stability -------------------------------------------------------------------------------

std::string stressValue(const glare::StressValue& v) {
    std::string s;
    for (const auto& [k, x] : v) s += (s.empty() ? "" : "<br>") + htmlEscape(k) + (k.empty() ? "" : " ") + fmt("%.4g", x);
    return s.empty() ? "—" : s;
}

std::string stressSection(const glare::StressReport& r, const glare::StressOptions& o) {
    const uint32_t size = o.size;
    std::string s = "<section id=\"stress\"><h2>Numerical stability</h2>\n<p><code>ps11 stress</code> on <code>" +
                    htmlEscape(r.hardware) +
                    "</code>: each 8-bit pitfall of GLARE.md §7 computed from its formula, measured on the card's real "
                    "ps_1_1 passes, and a fix that still fits ps_1_1 with its measured effect.</p>\n<table><tr><th>"
                    "pitfall</th><th>predicted</th><th>measured</th><th>fix</th><th>with the fix</th></tr>\n";
    for (const glare::StressItem& i : r.items)
        s += "<tr><td><code>" + htmlEscape(i.name) + "</code><br><small>" + htmlEscape(i.unit) + "</small></td><td>" +
             stressValue(i.predicted) + "</td><td>" + stressValue(i.measured) + "</td><td>" + htmlEscape(i.fix) +
             "</td><td>" + stressValue(i.measuredWithFix) + "</td></tr>\n";
    s += "</table>\n<div class=\"row\">";
    static const char* kColors[] = {"#c0392b", "#2471a3", "#7f8c8d", "#27ae60"};
    for (const glare::StressItem& i : r.items) {
        if (i.series.empty()) continue;
        if (i.name == "decimation_capture") {
            for (const auto& [name, cells] : i.series) {
                const int side = int(std::lround(std::sqrt(double(cells.size()))));
                s += "<div class=\"plot\">" + svgGrid(i.name + ": " + name, side, side, cells, "#c0392b") + "</div>";
            }
            continue;
        }
        std::vector<PlotSeries> lines;
        for (size_t k = 0; k < i.series.size(); ++k) {
            PlotSeries l{i.series[k].first, kColors[k % 4], {}, i.series[k].second, k + 1 == i.series.size()};
            for (size_t f = 0; f < l.y.size(); ++f) l.x.push_back(double(f));
            lines.push_back(l);
        }
        PlotAxes ax;
        ax.title = i.name;
        ax.xLabel = "frame";
        ax.yLabel = "levels";
        s += "<div class=\"plot\">" + svgLines(ax, lines) + "<p><small>" + htmlEscape(i.seriesUnit) + "</small></p></div>";
    }
    s += "</div>\n<h3>Quality metrics (GLARE.md §6), " + std::to_string(size) + "×" + std::to_string(size) +
         "</h3>\n<table><tr><th>technique</th><th>stability: energy</th><th>stability: peak</th><th>firefly share</th>"
         "<th>firefly area</th><th>DC gain</th><th>impulse gain</th><th>r50</th><th>r90</th><th>visible radius</th><th>"
         "anisotropy</th><th>band levels</th><th>largest step</th></tr>\n";
    for (const glare::TechniqueMetrics& m : r.metrics)
        s += "<tr><td>" + htmlEscape(m.technique) + "</td><td>" + fmt("%.3g", m.stabilityEnergy) + "</td><td>" +
             fmt("%.3g", m.stabilityPeak) + "</td><td>" + fmt("%.3g", m.fireflyShare) + "</td><td>" +
             std::to_string(m.fireflyArea) + "</td><td>" + fmt("%.3g", m.dcGain) + "</td><td>" + fmt("%.3g", m.impulseGain) +
             "</td><td>" + fmt("%.3g", m.r50) + "</td><td>" + fmt("%.3g", m.r90) + "</td><td>" +
             fmt("%.3g", m.visibilityRadius) + "</td><td>" + fmt("%.3g", m.anisotropy) + "</td><td>" +
             std::to_string(m.bandLevels) + "</td><td>" + std::to_string(m.bandStep) + "</td></tr>\n";
    int pass = 0;
    std::string failed;
    for (const glare::RobustnessCheck& k : r.robustness) {
        pass += k.pass;
        if (!k.pass) failed += "<li>" + htmlEscape(k.name + ": " + k.detail) + "</li>";
    }
    s += "</table>\n<p>Robustness (NaN, ±Inf and 10⁶ inputs in every technique; " + std::to_string(o.adaptationFrames) +
         " frames of adaptation): " +
         std::to_string(pass) + " of " + std::to_string(r.robustness.size()) + " checks pass.</p>" +
         (failed.empty() ? "" : "<ul class=\"bad\">" + failed + "</ul>") + "</section>\n";
    return s;
}

// ---- debug -----------------------------------------------------------------------------------

// `ps11 debug` of the adaptive glare amount on a grey 2x2 luminance (0x90 = 0.565: avg·min(4·avg, 1)
// stays 0.565 on the card, 4·avg² is 1.28 under ideal), with the shader written beside the report
// so the command shown can be run again.
bool debugTrace(Ctx& c, DebugTrace& d, std::string& command) {
    const std::string_view* text = glare::shaderText("adaptive_amount.psh");
    if (!text) {
        c.error = "no shader adaptive_amount.psh";
        return false;
    }
    const std::string path = c.dir + "/adaptive_amount.psh";
    if (!cli::writeFile(path, std::string(*text))) return false;
    std::vector<std::string> args = {path, "c2=0,0,0,0.025", "--hardware", std::string(c.cls->name)};
    for (int s = 0; s < 4; ++s) args.insert(args.end(), {"--tex" + std::to_string(s), "0xff909090"});
    command = "ps11 debug";
    for (const std::string& a : args) command += " " + a;
    EvalArgs ea;
    if (parseEvalArgs(args, "demo", "", ea) != cli::kOk || debugPixel(ea, d) != cli::kOk) {
        c.error = "the debug trace of " + path + " failed";
        return false;
    }
    return true;
}

std::string debugSection(const DebugTrace& d, const std::string& command) {
    std::string s = "<section id=\"debug\"><h2>One pixel, instruction by instruction</h2>\n<p><code>" +
                    htmlEscape(command) +
                    "</code>: the adaptive glare amount on " + htmlEscape(d.describe) +
                    " beside ideal, why they differ, and the first instruction where they part by more than one 8-bit "
                    "level (marked).</p>\n<table><tr><th>line</th><th>instruction</th><th>" + htmlEscape(d.hardware) +
                    "</th><th>ideal</th><th>Δ levels</th><th>why</th></tr>\n";
    for (size_t k = 0; k < d.rows.size(); ++k) {
        const DebugStep& st = d.rows[k];
        auto vec = [&](const std::array<float, 4>& v) {
            std::string x;
            for (int c = 0; c < 4; ++c)
                if (st.writes && ((st.mask >> c) & 1)) x += (x.empty() ? "" : " ") + fmt("%.4f", v[size_t(c)]);
            return x;
        };
        std::string why;
        for (const std::string& w : st.why) why += (why.empty() ? "" : ", ") + w;
        if (why.empty() && st.levels > 0) why = "(from its sources)";
        s += std::string("<tr") + (int(k) == d.firstDivergence ? " class=\"bad\"" : "") + "><td>" +
             std::to_string(st.line) + "</td><td><code>" + htmlEscape(st.text) + "</code></td><td>" + vec(st.emulated) +
             "</td><td>" + vec(st.ideal) + "</td><td>" + fmt("%.2f", st.levels) + "</td><td>" + htmlEscape(why) +
             "</td></tr>\n";
    }
    return s + "</table></section>\n";
}

const char* kStyle =
    "body{font-family:sans-serif;max-width:1320px;margin:auto;padding:0 16px;color:#222}"
    "h1{margin-bottom:0}nav a{margin-right:12px}section{margin-top:28px;border-top:1px solid #ddd}"
    "table{border-collapse:collapse;font-size:12px;margin:8px 0}td,th{border:1px solid #ccc;padding:3px 6px;"
    "text-align:left;vertical-align:top}th{background:#f4f4f4}.bad{background:#fde2e0}"
    ".row{display:flex;flex-wrap:wrap;gap:10px}figure{margin:4px}figcaption{font-size:11px;max-width:300px}"
    ".sheet figcaption{max-width:150px}.plot{border:1px solid #eee}code{font-size:12px}img{image-rendering:auto;"
    "border:1px solid #ccc}";

}  // namespace

int writeDemoReport(const DemoReportOptions& o) {
    Ctx c{o, o.outDir, {}, {}, {}, {}, {}, nullptr, {}};
    std::error_code ec;
    std::filesystem::create_directories(c.dir + "/img", ec);
    if (ec) {
        std::fprintf(stderr, "ps11: demo: cannot create %s: %s\n", (c.dir + "/img").c_str(), ec.message().c_str());
        return cli::kUserError;
    }
    c.cls = o.hardware ? o.hardware : resolveHardware(nullptr, 1, std::nullopt, 0).hardware;
    const uint32_t w = o.width ? o.width : o.quick ? 480 : 960, h = o.height ? o.height : o.quick ? 270 : 540;
    auto fail = [&](const std::string& what) {
        std::fprintf(stderr, "ps11: demo: %s: %s\n", what.c_str(), c.error.c_str());
        return cli::kUserError;
    };
    std::string glErr;
    c.glExact = ps11test::glRendererFactory("", glErr, false);
    if (c.glExact) {
        c.glNative = ps11test::glRendererFactory("", glErr, true);
        c.glDescription = ps11test::glRendererDescription();
    } else {
        c.glMissing = glErr;
    }
    c.progress("demo: writing " + c.dir + "/index.html (" + std::string(o.quick ? "quick" : "full") + ")");

    std::vector<TechniqueShow> shows;
    for (const glare::Technique* t : glare::techniques()) {
        TechniqueShow s;
        if (!showTechnique(c, *t, w, h, s)) return fail(std::string(t->name()));
        shows.push_back(std::move(s));
    }

    c.progress("fits: every pass against the limits and the range proof");
    const glare::FitsReport fits = glare::fitsReport();

    glare::SweepSpec spec;
    spec.techniques = glare::techniques();
    spec.qualities = o.quick ? std::vector<std::string>{"low", "published"}
                             : std::vector<std::string>{"low", "medium", "high", "published"};
    spec.hardware = {glare::SweepHardware{std::string(c.cls->name), c.cls, false}};
    spec.gl = bool(c.glNative);
    spec.glRenderer = c.glNative;
    spec.width = o.quick ? 480 : 1920;
    spec.height = o.quick ? 270 : 1080;
    spec.frames = o.quick ? 2 : 10;
    spec.threads = o.threads;
    std::vector<glare::SweepRow> rows;
    if (!glare::runSweep(spec, rows, c.error, [&](const std::string& line) { c.progress("bench: " + line); }))
        return fail("bench");
    glare::markPareto(rows);

    c.progress("stress: the 8-bit pitfalls, the quality metrics, robustness");
    glare::StressOptions so;
    so.hardware = c.cls;
    so.size = o.quick ? 64 : 128;
    so.adaptationFrames = o.quick ? 1000 : 10000;
    glare::StressReport stress;
    if (!glare::runStress(so, stress, c.error)) return fail("stress");

    c.progress("debug: the adaptive glare amount, one pixel");
    DebugTrace debug;
    std::string debugCommand;
    if (!debugTrace(c, debug, debugCommand)) return fail("debug");

    std::vector<PhotoShow> photoShows;
    std::string photosMissing;
    if (std::optional<std::vector<glare::Photo>> all = glare::listPhotos(photosMissing, o.photosDir)) {
        for (const glare::Photo& p : pickPhotos(*all, o.quick ? 1 : 3)) {
            PhotoShow ps;
            if (!showPhoto(c, p, ps)) return fail(p.name);
            photoShows.push_back(std::move(ps));
        }
    }

    std::string html = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>ps11 demo</title><style>" +
                       std::string(kStyle) + "</style></head><body>\n<h1>ps11: Direct3D 8/9 pixel shaders, emulated</h1>\n";
    html += "<p>ps11 " + htmlEscape(std::string(versionString())) +
            " assembles, validates and runs ps_1_1 … ps_1_4 with an explicit fixed-point precision model, emulates a "
            "Direct3D 9-style device, runs five classic glare techniques in real ps_1_1 assembly, and cross-checks "
            "every result against an OpenGL renderer. This page was written by <code>ps11 demo" +
            std::string(o.quick ? " --quick" : "") + "</code> on " + std::to_string(std::thread::hardware_concurrency()) +
            " hardware threads" + (c.glDescription.empty() ? "" : "; GL: " + htmlEscape(c.glDescription)) + ".</p>\n";
    html += "<nav><a href=\"#techniques\">techniques</a><a href=\"#fits\">fits ps_1_1</a><a href=\"#agreement\">emulator "
            "vs GL</a><a href=\"#bench\">time vs error</a><a href=\"#stress\">stability</a><a href=\"#debug\">debug</a>"
            "<a href=\"#photos\">photographs</a>"
            "</nav>\n";
    html += techniquesSection(c, shows, w, h);
    html += fitsSection(fits);
    html += agreementSection(c, shows);
    html += benchSection(c, rows, spec);
    html += stressSection(stress, so);
    html += debugSection(debug, debugCommand);
    html += photosSection(photoShows, photosMissing);
    html += "<footer><p>Written in " + fmt("%.1f", c.progress.seconds()) + " s.</p></footer></body></html>\n";
    if (!cli::writeFile(c.dir + "/index.html", html)) return cli::kUserError;
    c.progress("done");

    std::printf("ps11 demo: %zu techniques on their scenes at %ux%u, emulated %s", shows.size(), w, h,
                std::string(c.cls->name).c_str());
    std::printf(c.glExact ? " and cross-checked on GL (%s)\n" : " (no GL: %s)\n",
                (c.glExact ? c.glDescription : c.glMissing).c_str());
    for (const TechniqueShow& t : shows)
        std::printf("  %-9s error against ideal: max %3d, mean %.3f levels\n", std::string(t.t->name()).c_str(),
                    t.emuError.max, t.emuError.mean);
    std::printf("report: %s/index.html (open it in a browser)\n", c.dir.c_str());
    return cli::kOk;
}

}  // namespace ps11
