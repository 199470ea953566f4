// `ps11 bench` (tools/cmd_bench.h, docs/bench.md): the command line of the sweep in glare/sweep.h —
// parses the options into a SweepSpec, runs it with progress on stderr, prints the table and the
// Pareto front per technique, or {"rows": [...]} with --json.
#include "tools/cmd_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "emu/image_file.h"
#include "glare/photos.h"
#include "glare/scene.h"
#include "glare/sweep.h"
#include "ps11/hardware.h"
#include "tools/cli_util.h"
#include "runner/gl_backend.h"

namespace ps11 {

namespace {

constexpr const char* kBenchUsage =
    "usage: ps11 bench [--technique T|all] [--quality Q|all] [--set name=v1,v2,...]... [--hardware H|all]\n"
    "                  [--backend emu|gl|both] [--gl-mode native|exact] [--gl osmesa|egl] [--scene S | --in IMG|DIR]\n"
    "                  [--exposure STOPS] [--size WxH] [--frames N] [--json]\n"
    "  T, Q and H also take comma-separated lists; --hardware takes `ideal` (the reference profile) too.\n"
    "  Defaults: every technique on its own scene, published quality, the default card, both renderers\n"
    "  (GL in native mode), 1920x1080, 20 timed frames after one warm-up.\n";

int benchUsage(const std::string& msg) {
    std::cerr << "ps11 bench: " << msg << "\n" << kBenchUsage;
    return cli::kUsage;
}

std::vector<std::string> splitList(const std::string& s) {
    std::vector<std::string> out;
    size_t start = 0;
    while (true) {
        const size_t comma = s.find(',', start);
        out.push_back(s.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

// A JSON number, or null where it is not finite (PSNR of identical images is +inf).
nlohmann::ordered_json number(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); }

nlohmann::ordered_json errorJson(const glare::ImageError& e) {
    return {{"max_levels", e.max}, {"mean_levels", number(e.mean)}, {"differing_pct", number(e.overOnePercent)},
            {"psnr", number(e.psnr)}};
}

nlohmann::ordered_json rowJson(const glare::SweepRow& r) {
    const glare::Technique& t = *glare::findTechnique(r.technique);
    nlohmann::ordered_json settings = nlohmann::ordered_json::object();
    for (const glare::ParamInfo& p : t.params()) {
        const double v = r.settings.at(p.name);
        if (p.integer)
            settings[p.name] = int64_t(std::llround(v));
        else if (p.choices.empty())
            settings[p.name] = number(v);
        else
            settings[p.name] = glare::settingText(p, v);
    }
    nlohmann::ordered_json j = {{"technique", r.technique},
                        {"quality", r.quality},
                        {"settings", settings},
                        {"hardware", r.hardware},
                        {"precision", r.precision},
                        {"backend", r.backend},
                        {"scene", r.scene},
                        {"size", {r.width, r.height}},
                        {"frames", r.frames},
                        {"ms_median", number(r.msMedian)},
                        {"ms_min", number(r.msMin)},
                        {"ms_max", number(r.msMax)},
                        {"error", errorJson(r.error)},
                        {"pareto", r.pareto}};
    if (!r.glMode.empty()) j["gl_mode"] = r.glMode;
    if (r.intendedError) j["intended_error"] = errorJson(*r.intendedError);
    return j;
}

std::string psnrText(double psnr) {
    char b[32];
    if (!std::isfinite(psnr)) return "inf";
    std::snprintf(b, sizeof b, "%.1f", psnr);
    return b;
}

std::string sweptText(const glare::SweepRow& r) {
    std::string s;
    for (const auto& [n, v] : r.swept) s += (s.empty() ? "" : ",") + n + "=" + v;
    return s.empty() ? "-" : s;
}

std::string backendText(const glare::SweepRow& r) { return r.glMode.empty() ? r.backend : r.backend + "-" + r.glMode; }

void printTable(const std::vector<glare::SweepRow>& rows, const glare::SweepSpec& spec) {
    std::printf("run time against error: %d timed frame(s) per row after one warm-up; error of the 8-bit output over RGB\n"
                "against the technique's ideal reference (same settings, same input), in 8-bit levels\n\n",
                spec.frames);
    size_t sw = 8, cw = 7;
    for (const glare::SweepRow& r : rows) sw = std::max(sw, sweptText(r).size()), cw = std::max(cw, r.scene.size());
    std::printf("%-9s %-*s %-9s %-10s %-*s %-10s %-5s %-9s %8s %8s %8s %5s %7s %7s %6s | %5s %7s %7s %6s  %s\n", "technique",
                int(cw), "scene", "size", "quality", int(sw), "settings", "hardware", "prec", "backend", "ms med", "min", "max",
                "max", "mean", ">1 %", "PSNR", "max", "mean", ">1 %", "PSNR", "front");
    for (const glare::SweepRow& r : rows) {
        char intended[64] = "    -       -       -      -";
        if (r.intendedError)
            std::snprintf(intended, sizeof intended, "%5d %7.3f %7.2f %6s", r.intendedError->max, r.intendedError->mean,
                          r.intendedError->overOnePercent, psnrText(r.intendedError->psnr).c_str());
        const std::string size = std::to_string(r.width) + "x" + std::to_string(r.height);
        std::printf("%-9s %-*s %-9s %-10s %-*s %-10s %-5s %-9s %8.2f %8.2f %8.2f %5d %7.3f %7.2f %6s | %s  %s\n",
                    r.technique.c_str(), int(cw), r.scene.c_str(), size.c_str(), r.quality.c_str(), int(sw), sweptText(r).c_str(),
                    r.hardware.c_str(), r.precision.c_str(), backendText(r).c_str(), r.msMedian, r.msMin, r.msMax, r.error.max,
                    r.error.mean, r.error.overOnePercent, psnrText(r.error.psnr).c_str(), intended, r.pareto ? "*" : "");
    }
    std::printf("\n(ms: the technique's passes per frame, median/min/max; >1 %%: pixels whose largest channel differs by more\n"
                " than one level; PSNR in dB, inf when identical; left of | the error against the ideal reference, right of it\n"
                " against the intended math (pyramid, glow; docs/bench.md); front: no other row of the technique is both\n"
                " faster and more accurate — lower mean error against ideal, ties broken by max)\n\n");
    std::printf("Pareto front (median ms against mean error vs ideal), fastest first:\n");
    std::map<std::string, std::vector<const glare::SweepRow*>> fronts;
    std::vector<std::string> order;
    for (const glare::SweepRow& r : rows) {
        const std::string key = r.technique + " on " + r.scene + " " + std::to_string(r.width) + "x" + std::to_string(r.height);
        if (!fronts.count(key)) order.push_back(key);
        if (r.pareto) fronts[key].push_back(&r);
        else fronts[key];
    }
    for (const std::string& key : order) {
        std::vector<const glare::SweepRow*>& f = fronts[key];
        std::sort(f.begin(), f.end(), [](const glare::SweepRow* a, const glare::SweepRow* b) { return a->msMedian < b->msMedian; });
        std::printf("  %s:\n", key.c_str());
        for (const glare::SweepRow* r : f)
            std::printf("    %8.2f ms  mean %.3f  max %3d  %s %s %s %s\n", r->msMedian, r->error.mean, r->error.max,
                        r->quality.c_str(), sweptText(*r).c_str(), r->hardware.c_str(), backendText(*r).c_str());
    }
}

}  // namespace

int cmdBench(const std::vector<std::string>& args) {
    std::string techniqueArg = "all", qualityArg = "published", hardwareArg, backend = "both", glMode = "native", glKind;
    std::string scene, in;
    std::vector<std::string> sets;
    uint32_t width = 0, height = 0;
    int frames = 20;
    float exposure = 0;
    bool json = false, glModeGiven = false;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        std::string v;
        auto value = [&]() {
            if (i + 1 >= args.size()) return false;
            v = args[++i];
            return true;
        };
        if (a == "--help" || a == "-h") {
            std::cout << kBenchUsage;
            return cli::kOk;
        } else if (a == "--json") {
            json = true;
        } else if (a == "--technique" || a == "-t") {
            if (!value() || v.empty()) return benchUsage("--technique needs a name, a comma-separated list or all");
            techniqueArg = v;
        } else if (a == "--quality") {
            if (!value() || v.empty()) return benchUsage("--quality needs low, medium, high, published or all");
            qualityArg = v;
        } else if (a == "--set") {
            if (!value()) return benchUsage("--set needs name=v1,v2,...");
            sets.push_back(v);
        } else if (a == "--hardware") {
            if (!value() || v.empty()) return benchUsage("--hardware needs a class, a comma-separated list or all");
            hardwareArg = v;
        } else if (a == "--backend") {
            if (!value() || (v != "emu" && v != "gl" && v != "both"))
                return benchUsage("--backend takes emu, gl or both" + (v.empty() ? std::string() : ", not '" + v + "'"));
            backend = v;
        } else if (a == "--gl-mode") {
            if (!value() || (v != "native" && v != "exact"))
                return benchUsage("--gl-mode takes native or exact" + (v.empty() ? std::string() : ", not '" + v + "'"));
            glMode = v;
            glModeGiven = true;
        } else if (a == "--gl") {
            if (!value() || (v != "osmesa" && v != "egl")) return benchUsage("--gl takes osmesa or egl");
            glKind = v;
        } else if (a == "--scene") {
            if (!value() || v.empty()) return benchUsage("--scene needs a name");
            scene = v;
        } else if (a == "--in") {
            if (!value() || v.empty()) return benchUsage("--in needs an image file or a folder of them");
            in = v;
        } else if (a == "--size") {
            if (!value() || !cli::parseSize(v, width, height, cli::kMaxSizeSide, cli::kMinGlareFrameSide))
                return benchUsage("--size takes " + cli::sizeRule(cli::kMaxSizeSide, cli::kMinGlareFrameSide) +
                                  (v.empty() ? std::string() : ", not '" + v + "'"));
        } else if (a == "--frames") {
            if (!value() || !cli::parseCount(v, 1, 10000, frames))
                return benchUsage("--frames takes a count 1..10000" + (v.empty() ? std::string() : ", not '" + v + "'"));
        } else if (a == "--exposure") {
            char* end = nullptr;
            if (!value()) return benchUsage("--exposure needs a number of stops");
            exposure = std::strtof(v.c_str(), &end);
            if (end == v.c_str() || *end || !std::isfinite(exposure) || std::fabs(exposure) > 64)
                return benchUsage("--exposure takes stops in -64 .. 64");
        } else {
            return benchUsage(cli::unknownOption(a, {"--technique", "--quality", "--set", "--hardware", "--backend",
                                                     "--gl-mode", "--gl", "--scene", "--in", "--exposure", "--size",
                                                     "--frames", "--json", "--help"}));
        }
    }
    if (!scene.empty() && !in.empty()) return benchUsage("give one input: --scene NAME or --in IMAGE, not both");
    if (!in.empty() && width) return benchUsage("--size applies to scenes; an --in image keeps its own size");
    if (glModeGiven && backend == "emu") return benchUsage("--gl-mode needs --backend gl or both");

    glare::SweepSpec spec;
    spec.frames = frames;
    spec.width = width ? width : 1920;
    spec.height = height ? height : 1080;
    spec.scene = scene;
    spec.glNative = glMode == "native";
    spec.emu = backend != "gl";
    spec.gl = backend != "emu";
    // --technique
    if (techniqueArg == "all") {
        spec.techniques = glare::techniques();
    } else {
        for (const std::string& name : splitList(techniqueArg)) {
            const glare::Technique* t = glare::findTechnique(name);
            if (!t) return benchUsage("--technique: " + glare::unknownTechniqueMessage(name));
            spec.techniques.push_back(t);
        }
    }
    // --quality
    spec.qualities.clear();
    if (qualityArg == "all") {
        for (std::string_view p : glare::kPresetNames) spec.qualities.emplace_back(p);
    } else {
        for (const std::string& q : splitList(qualityArg)) {
            if (!glare::presetSettings(*spec.techniques.front(), q))
                return benchUsage("--quality: unknown preset '" + q + "' (low, medium, high, published or all)");
            spec.qualities.push_back(q);
        }
    }
    // --hardware
    if (hardwareArg == "all") {
        spec.hardware = glare::allSweepHardware();
    } else if (!hardwareArg.empty()) {
        for (const std::string& name : splitList(hardwareArg)) {
            std::optional<glare::SweepHardware> h = glare::findSweepHardware(name);
            if (!h) return benchUsage("--hardware: " + unknownHardwareMessage(name) + ", ideal or all");
            spec.hardware.push_back(*h);
        }
    }
    // --set name=v1,v2: every value checked against every selected technique that has the setting.
    for (const std::string& s : sets) {
        const size_t eq = s.find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == s.size())
            return benchUsage("--set takes name=v1,v2,..., not '" + s + "'");
        glare::SweepSetting setting{s.substr(0, eq), splitList(s.substr(eq + 1))};
        bool any = false;
        for (const glare::Technique* t : spec.techniques) {
            const bool has = std::any_of(t->params().begin(), t->params().end(),
                                         [&](const glare::ParamInfo& p) { return p.name == setting.name; });
            if (!has) continue;
            any = true;
            for (const std::string& value : setting.values) {
                glare::Settings check = *glare::presetSettings(*t, "published");
                std::string err;
                if (value.empty()) return benchUsage("--set " + s + ": an empty value");
                if (!glare::applySetting(*t, check, setting.name + "=" + value, err)) return benchUsage("--set " + s + ": " + err);
            }
        }
        if (!any) {
            std::string names;
            for (const glare::Technique* t : spec.techniques) names += (names.empty() ? "" : ", ") + std::string(t->name());
            return benchUsage("--set " + s + ": no setting '" + setting.name + "' in " + names +
                              " (`ps11 glare --list` lists the settings)");
        }
        spec.settings.push_back(std::move(setting));
    }
    // The input.
    if (!scene.empty()) {
        std::string err;
        if (!glare::makeScene(scene, err)) return benchUsage("--scene: " + err);
    }
    // --in DIR: each image file of the folder in turn (glare::imageFilesIn), its rows named after it.
    std::vector<std::string> inputs;
    if (!in.empty()) {
        std::error_code ec;
        if (std::filesystem::is_directory(in, ec)) {
            std::string err;
            std::optional<std::vector<std::string>> files = glare::imageFilesIn(in, err);
            if (!files || files->empty()) {
                std::cerr << "ps11 bench: --in: "
                          << (files ? in + ": no image files (*.png, *.hdr, *.exr) in the folder" : err) << "\n";
                return cli::kUserError;
            }
            inputs = *files;
        } else {
            inputs.push_back(in);
        }
    }
    const auto loadInput = [&](const std::string& path) {
        std::string err;
        std::optional<emu::LoadedImage> loaded = emu::readImage(path, err);
        if (!loaded) {
            std::cerr << "ps11 bench: --in: " << err << "\n";
            return false;
        }
        spec.image = loaded->hdr ? emu::exposeUnclamped(loaded->image, exposure) : loaded->image;
        spec.imageName = path;
        return true;
    };
    if (!inputs.empty() && !loadInput(inputs.front())) return cli::kUserError;
    if (spec.gl) {
        setenv("LP_NUM_THREADS", "2", 0);  // llvmpipe's threads, as the peer is measured (PERF.md); read when its screen is made
        std::string err;
        spec.glRenderer = ps11test::glRendererFactory(glKind, err, spec.glNative);
        if (!spec.glRenderer) {
            std::cerr << "ps11 bench: --backend " << backend << ": the GL renderer is not available: " << err << "\n";
            return cli::kUserError;
        }
    }

    std::vector<glare::SweepRow> rows;
    for (size_t i = 0; i < std::max<size_t>(1, inputs.size()); ++i) {
        if (i > 0 && !loadInput(inputs[i])) return cli::kUserError;
        std::vector<glare::SweepRow> these;
        std::string err;
        const bool ok = glare::runSweep(spec, these, err, [](const std::string& line) {
            std::fprintf(stderr, "ps11 bench: %s\n", line.c_str());
        });
        if (!ok) {
            std::cerr << "ps11 bench: " << err << "\n";
            return cli::kUserError;
        }
        rows.insert(rows.end(), these.begin(), these.end());
    }
    if (json) {
        nlohmann::ordered_json out = {{"rows", nlohmann::ordered_json::array()}};
        for (const glare::SweepRow& r : rows) out["rows"].push_back(rowJson(r));
        std::cout << out.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
        return cli::kOk;
    }
    if (spec.gl && !ps11test::glRendererDescription().empty())
        std::printf("GL renderer: %s\n", ps11test::glRendererDescription().c_str());
    printTable(rows, spec);
    return cli::kOk;
}

}  // namespace ps11
