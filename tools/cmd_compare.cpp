// `ps11 compare` (tools/cmd_compare.h): a test file's draws, a bare shader over random inputs, or
// random programs, drawn by the emu device's software renderer and by the GL renderer side by
// side; each draw's render target compared pixel by pixel.
#include "tools/cmd_compare.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <variant>

#include "emu/image_file.h"
#include "ps11/assembler.h"
#include "ps11/hardware.h"
#include "ps11/json_internal.h"
#include "ps11/testfile.h"
#include "ps11/validator.h"
#include "tools/cli_util.h"
#include "runner/gl_backend.h"
#include "runner/random_program.h"
#include "runner/test_draw.h"

namespace ps11 {

namespace {

// compare's --size stops at 4096 a side, below the other commands' cli::kMaxSizeSide.
constexpr uint32_t kMaxCompareSide = 4096;

constexpr const char* kUsage =
    "usage: ps11 compare SHADER.psh|FILE.ps11test [--size WxH] [--seed S] [--hardware H] [--precision P]\n"
    "                    [--heatmap OUT.png] [--json] [--gl osmesa|egl] [--gl-mode exact|native] [--gl-filtering] [-v]\n"
    "       ps11 compare --random N [--seed S] [--minor 1..4] [--out DIR] [--json] [--gl osmesa|egl]\n"
    "  --gl-mode native: GL as a GPU driver runs the draws (not bit-exact by design); reports how far it\n"
    "                    lands from the emulated card and from the ideal profile (exit 1 only on refusals)\n";

int usageError(const std::string& msg) {
    std::cerr << "ps11 compare: " << msg << "\n" << kUsage;
    return cli::kUsage;
}

struct Options {
    const HardwareClass* hardware = nullptr;
    std::optional<Precision> precision;
    uint32_t width = 64, height = 64;
    uint64_t seed = 1;
    std::string heatmap;
    bool json = false;
    long random = -1;  // --random N
    int minor = 0;
    std::string outDir = ".";
    bool glFiltering = false;  // float profiles: GL's texture unit filters (GlRendererOptions)
    bool native = false;       // --gl-mode native: measured against the card and against ideal
    bool verbose = false;      // -v: the first differing pixels of each draw
};

// One draw compared.
struct DrawDiff {
    uint32_t line = 0;
    uint64_t pixels = 0, exact = 0, overOne = 0;
    uint64_t distinctEmu = 0, distinctGl = 0;  // distinct colours in each target
    double maxDiff = 0;                        // 8-bit levels, or values on float targets
    double sumDiff = 0;                        // of every pixel's largest channel difference (mean)
    bool values = false;
};

struct Report {
    std::vector<DrawDiff> draws;
    std::vector<DrawDiff> idealDraws;  // --gl-mode native: GL against the ideal profile, per draw
    std::vector<std::pair<uint32_t, std::string>> unsupported;  // line, why the GL renderer refused
    std::string error;                                          // the input itself is wrong
    std::vector<Vec4> emuPixels, glPixels;                      // the last draw's targets
    uint32_t width = 0, height = 0;
    bool values = false;

    uint64_t sum(uint64_t DrawDiff::*f) const {
        uint64_t n = 0;
        for (const DrawDiff& d : draws) n += d.*f;
        return n;
    }
    double maxDiff() const {
        double m = 0;
        for (const DrawDiff& d : draws) m = std::max(m, d.maxDiff);
        return m;
    }
    // Within the cross-check's target and nothing refused.
    bool agrees() const { return error.empty() && unsupported.empty() && sum(&DrawDiff::overOne) == 0; }
};

DrawDiff diffTargets(const std::vector<Vec4>& a, const std::vector<Vec4>& b, bool values) {
    DrawDiff d;
    d.values = values;
    d.pixels = a.size();
    for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
        double m = 0;
        for (int c = 0; c < 4; ++c) {
            const double x = a[i][size_t(c)], y = b[i][size_t(c)];
            const double diff = (x == y || (x != x && y != y)) ? 0.0 : std::fabs(x - y);
            m = std::max(m, diff != diff ? 1e30 : diff);
        }
        d.exact += m == 0;
        d.overOne += m > (values ? 1e-4 : 1.0);
        d.maxDiff = std::max(d.maxDiff, m);
        d.sumDiff += std::min(m, 1e30);
    }
    auto distinct = [](std::vector<Vec4> v) {
        std::sort(v.begin(), v.end());
        return uint64_t(std::unique(v.begin(), v.end()) - v.begin());
    };
    d.distinctGl = distinct(a);
    d.distinctEmu = distinct(b);
    return d;
}

// Runs every draw of a .ps11test on both renderers (probes and evals are not compared).
void compareText(const std::string& text, const std::string& path, const Options& opts,
                 const ps11test::RendererFactory& gl, Report& report) {
    TestFile file;
    std::vector<TestFileError> errors;
    if (!parseTestFile(text, path, file, errors)) {
        for (const TestFileError& e : errors) report.error += formatTestFileError(path, e) + "\n";
        return;
    }
    std::optional<Program> program;
    Diagnostics diags;
    if (file.pixelShader.present()) {
        program = parseAssembly(file.pixelShader.textWithFileLines(), path, AssembleOptions{}, diags);
        if (program) validate(*program, diags);
        if (!program || diags.hasErrors()) {
            report.error = diags.formatAll();
            return;
        }
    }
    const RequireDesc& req = file.require;
    const int minor = program ? program->version.minor : req.versionMinor.value;
    const HardwareClass* named = opts.hardware ? opts.hardware : req.hardware.value;
    std::optional<Precision> precision = opts.precision;
    if (!precision && req.precision.isSet()) precision = req.precision.value;
    const HardwareConfig hw = resolveHardware(named, minor, precision, req.maxValue.value);
    std::string error;
    std::unique_ptr<ps11test::DrawRunner> emu =
        ps11test::DrawRunner::create(file, path, program ? &*program : nullptr, hw, error);
    if (!emu) {
        report.error = error;
        return;
    }
    std::unique_ptr<ps11test::DrawRunner> glr =
        ps11test::DrawRunner::create(file, path, program ? &*program : nullptr, hw, error, true, gl);
    // Native mode: the same draws under `ideal` on the emulator, the other end of the distance.
    std::unique_ptr<ps11test::DrawRunner> ideal;
    if (opts.native) {
        const HardwareConfig ihw = resolveHardware(named, minor, Precision::Ideal, req.maxValue.value);
        ideal = ps11test::DrawRunner::create(file, path, program ? &*program : nullptr, ihw, error);
        if (!ideal) {
            report.error = error;
            return;
        }
    }
    if (!glr) {
        report.unsupported.emplace_back(0, error);
        return;
    }
    const HardwareClass& cls = *hw.hardware;
    for (const TestCommand& cmd : file.commands) {
        if (!std::holds_alternative<DrawQuad>(cmd.op) && !std::holds_alternative<DrawPrimitives>(cmd.op)) continue;
        if (!cmd.onlyIf.matches(Backend::Emu, hw.precision, cls) || !cmd.onlyIf.matches(Backend::Gl, hw.precision, cls))
            continue;
        if (!emu->draw(cmd, error)) {
            report.error = error;
            return;
        }
        if (!glr->draw(cmd, error)) {
            report.unsupported.emplace_back(cmd.line, error);
            return;  // the targets part here: later draws would compare different inputs
        }
        if (!emu->targetPixels(report.emuPixels, error) || !glr->targetPixels(report.glPixels, error)) {
            report.error = error;
            return;
        }
        report.width = emu->width(), report.height = emu->height();
        report.values = emu->floatTarget();
        DrawDiff d = diffTargets(report.glPixels, report.emuPixels, report.values);
        d.line = cmd.line;
        report.draws.push_back(d);
        if (ideal) {
            std::vector<Vec4> idealPixels;
            if (!ideal->draw(cmd, error) || !ideal->targetPixels(idealPixels, error)) {
                report.error = error;
                return;
            }
            DrawDiff di = diffTargets(report.glPixels, idealPixels, report.values);
            di.line = cmd.line;
            report.idealDraws.push_back(di);
        }
        if (opts.verbose && d.exact < d.pixels) {
            int shown = 0;
            for (size_t i = 0; i < report.emuPixels.size() && shown < 20; ++i) {
                if (report.emuPixels[i] == report.glPixels[i]) continue;
                ++shown;
                std::cerr << path << ":" << cmd.line << ": pixel (" << i % report.width << ", " << i / report.width
                          << "): emu";
                for (float v : report.emuPixels[i]) std::cerr << " " << v;
                std::cerr << ", gl";
                for (float v : report.glPixels[i]) std::cerr << " " << v;
                std::cerr << "\n";
            }
        }
    }
}

std::string number(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

// Native mode's distance of GL from one reference over every draw: max and mean |d|, % of pixels
// more than one level (1e-4 on float targets) apart.
struct Distance {
    double max = 0, mean = 0, overOnePct = 0;
};
Distance distanceOf(const std::vector<DrawDiff>& draws) {
    Distance d;
    uint64_t pixels = 0, over = 0;
    double sum = 0;
    for (const DrawDiff& x : draws) pixels += x.pixels, over += x.overOne, sum += x.sumDiff, d.max = std::max(d.max, x.maxDiff);
    d.mean = pixels ? sum / double(pixels) : 0;
    d.overOnePct = pixels ? 100.0 * double(over) / double(pixels) : 0;
    return d;
}

void printReport(const std::string& path, const Report& r, const Options& opts) {
    const Distance card = distanceOf(r.draws), ideal = distanceOf(r.idealDraws);
    if (opts.json) {
        // Numbers with the digits the old output had (ostream's default: %g).
        auto num = [](double v) { return json::rounded(v, "%g"); };
        json::Json j;
        j["file"] = path;
        j["gl_mode"] = opts.native ? "native" : "exact";
        j["pixels"] = r.sum(&DrawDiff::pixels);
        j["exact"] = r.sum(&DrawDiff::exact);
        j["over_one"] = r.sum(&DrawDiff::overOne);
        j["max_diff"] = num(r.maxDiff());
        json::Json draws = json::Json::array();
        for (const DrawDiff& d : r.draws)
            draws.push_back({{"line", d.line},
                             {"pixels", d.pixels},
                             {"exact", d.exact},
                             {"over_one", d.overOne},
                             {"max_diff", num(d.maxDiff)},
                             {"unit", d.values ? "value" : "level"},
                             {"distinct_emu", d.distinctEmu},
                             {"distinct_gl", d.distinctGl}});
        j["draws"] = std::move(draws);
        json::Json unsupported = json::Json::array();
        for (const auto& [line, why] : r.unsupported) unsupported.push_back({{"line", line}, {"why", why}});
        j["unsupported"] = std::move(unsupported);
        if (opts.native) {
            auto distance = [&](const Distance& x) {
                return json::Json{{"max", num(x.max)}, {"mean", num(x.mean)}, {"over_one_pct", num(x.overOnePct)}};
            };
            j["vs_card"] = distance(card);
            j["vs_ideal"] = distance(ideal);
        }
        j["gl"] = ps11test::glRendererDescription();
        std::cout << json::dump(j) << "\n";
        return;
    }
    std::cout << "gl: " << ps11test::glRendererDescription() << "\n";
    for (const DrawDiff& d : r.draws)
        std::cout << path << ":" << d.line << ": draw: " << d.pixels << " pixels, " << d.exact << " exact, "
                  << d.overOne << " more than " << (d.values ? "1e-4" : "one level") << " apart, max |d| "
                  << number(d.maxDiff) << (d.values ? "" : " levels") << "; distinct colours: " << d.distinctEmu
                  << " emu, " << d.distinctGl << " gl\n";
    for (const auto& [line, why] : r.unsupported)
        std::cout << path << ":" << line << ": unsupported on gl: " << why << "\n";
    const uint64_t pixels = r.sum(&DrawDiff::pixels), exact = r.sum(&DrawDiff::exact);
    std::cout << "total: " << r.draws.size() << (r.draws.size() == 1 ? " draw, " : " draws, ") << pixels << " pixels, "
              << exact << " exact (" << (pixels ? 100.0 * double(exact) / double(pixels) : 100.0) << " %), "
              << r.sum(&DrawDiff::overOne) << " past the target, max |d| " << number(r.maxDiff()) << "\n";
    if (opts.native) {
        const char* unit = r.values ? "" : " levels";
        std::cout << "gl native against the emulated card: max |d| " << number(card.max) << unit << ", mean "
                  << number(card.mean) << unit << ", " << number(card.overOnePct) << " % of pixels more than "
                  << (r.values ? "1e-4" : "one level") << " apart\n"
                  << "gl native against ideal: max |d| " << number(ideal.max) << unit << ", mean " << number(ideal.mean)
                  << unit << ", " << number(ideal.overOnePct) << " % of pixels more than "
                  << (r.values ? "1e-4" : "one level") << " apart\n";
    }
}

// The heat map of the last draw: black = equal, blue = one level (or <= 1e-4) apart, red up
// to white the further apart.
bool writeHeatmap(const std::string& out, const Report& r) {
    emu::RgbaImage img;
    img.width = r.width, img.height = r.height;
    img.rgba.assign(size_t(r.width) * r.height * 4, 0);
    for (size_t i = 0; i < size_t(r.width) * r.height && i < r.emuPixels.size() && i < r.glPixels.size(); ++i) {
        double m = 0;
        for (int c = 0; c < 4; ++c) {
            const double d = std::fabs(double(r.emuPixels[i][size_t(c)]) - double(r.glPixels[i][size_t(c)]));
            m = std::max(m, d != d ? 1e30 : d);
        }
        uint8_t* p = &img.rgba[i * 4];
        p[3] = 255;
        const double unit = r.values ? 1e-4 : 1.0;
        if (m == 0) continue;
        if (m <= unit) {
            p[2] = 255;
            continue;
        }
        const double t = std::min(1.0, std::log2(m / unit) / 8.0);  // 2 .. 256 units: red to white
        p[0] = 255;
        p[1] = p[2] = uint8_t(std::lround(t * 255.0));
    }
    std::string error;
    if (!emu::writePng(out, img, error)) {
        std::cerr << "ps11 compare: " << error << "\n";
        return false;
    }
    return true;
}

// A bare shader as a test file: random textures of the formats its instructions need, random
// interpolants and constants, one full-target draw (runner/random_program.h).
std::optional<std::string> shaderCase(const std::string& source, const std::string& path, const Options& opts) {
    Diagnostics diags;
    std::optional<Program> program = parseAssembly(source, path, AssembleOptions{}, diags);
    if (program) validate(*program, diags);
    if (!program || diags.hasErrors()) {
        std::cerr << diags.formatAll();
        return std::nullopt;
    }
    std::vector<std::string> lines;
    std::istringstream in(source);
    std::string line;
    bool versionSeen = false;
    while (std::getline(in, line)) {
        if (!versionSeen && line.find("ps_1_") != std::string::npos) {
            versionSeen = true;
            const size_t at = line.find("ps_1_") + 6;
            if (at < line.size()) lines.push_back(line.substr(at));  // anything after the version
            continue;
        }
        lines.push_back(line);
    }
    std::mt19937_64 rng(opts.seed);
    ps11test::RandomCaseOptions ro;
    ro.width = int(opts.width), ro.height = int(opts.height);
    return ps11test::caseForProgram(rng, program->version.minor, lines, ro).testText;
}

int runRandom(const Options& opts, const ps11test::RendererFactory& gl) {
    uint64_t programs = 0, pixels = 0, exact = 0, overOne = 0;
    double maxDiff = 0;
    std::vector<std::pair<uint64_t, std::string>> mismatches;
    ps11test::RandomCaseOptions ro;
    ro.minor = opts.minor;
    for (long i = 0; i < opts.random; ++i) {
        const uint64_t seed = opts.seed + uint64_t(i);
        std::mt19937_64 rng(seed);
        const ps11test::RandomCase c = ps11test::randomCase(rng, ro);
        Report r;
        compareText(c.testText, "random-" + std::to_string(seed), opts, gl, r);
        ++programs;
        pixels += r.sum(&DrawDiff::pixels);
        exact += r.sum(&DrawDiff::exact);
        overOne += r.sum(&DrawDiff::overOne);
        maxDiff = std::max(maxDiff, r.maxDiff());
        if (r.agrees()) continue;
        auto stillFails = [&](const ps11test::RandomCase& k) {
            Report s;
            compareText(k.testText, "shrink", opts, gl, s);
            return s.error.empty() && !s.agrees();
        };
        const ps11test::RandomCase small = ps11test::shrinkCase(c, stillFails);
        Report sr;
        compareText(small.testText, "shrunk", opts, gl, sr);
        std::ostringstream head;
        head << "% ps11 compare --random: seed " << seed << ", the emulator and the GL renderer disagree\n"
             << "% (" << (sr.unsupported.empty() ? "" : "gl refuses: " + sr.unsupported[0].second + "; ")
             << sr.sum(&DrawDiff::overOne) << " pixels past the target, max |d| " << number(sr.maxDiff())
             << "); shrunk from " << c.lines.size() << " to " << small.lines.size() << " lines.\n";
        const std::string out =
            (std::filesystem::path(opts.outDir) / ("compare_random_" + std::to_string(seed) + ".ps11test")).string();
        if (!cli::writeFile(out, head.str() + small.testText)) return cli::kUserError;
        mismatches.emplace_back(seed, out);
        if (!opts.json)
            std::cout << "seed " << seed << ": mismatch, shrunk to " << small.lines.size() << " lines: " << out
                      << std::endl;  // at once: a long run may be stopped
    }
    if (opts.json) {
        json::Json j;
        j["programs"] = programs;
        j["pixels"] = pixels;
        j["exact"] = exact;
        j["over_one"] = overOne;
        j["max_diff"] = json::rounded(maxDiff, "%g");
        json::Json list = json::Json::array();
        for (const auto& [seed, file] : mismatches) list.push_back({{"seed", seed}, {"file", file}});
        j["mismatches"] = std::move(list);
        j["gl"] = ps11test::glRendererDescription();
        std::cout << json::dump(j) << "\n";
    } else {
        std::cout << "gl: " << ps11test::glRendererDescription() << "\n"
                  << "random: " << programs << " programs (seeds " << opts.seed << ".." << opts.seed + programs - 1
                  << "), " << pixels << " pixels, " << exact << " exact ("
                  << (pixels ? 100.0 * double(exact) / double(pixels) : 100.0) << " %), " << overOne
                  << " past the target, max |d| " << number(maxDiff) << "; " << mismatches.size()
                  << " mismatching programs\n";
    }
    return mismatches.empty() ? cli::kOk : cli::kUserError;
}

}  // namespace

int cmdCompare(const std::vector<std::string>& args) {
    Options opts;
    std::string input;
    std::string glName;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&](std::string& out) {
            if (i + 1 >= args.size()) return false;
            out = args[++i];
            return true;
        };
        std::string v;
        if (a == "--help" || a == "-h") {
            std::cout << kUsage;
            return cli::kOk;
        } else if (a == "--json") {
            opts.json = true;
        } else if (a == "-v" || a == "--verbose") {
            opts.verbose = true;
        } else if (a == "--gl-filtering") {
            opts.glFiltering = true;
        } else if (a == "--size") {
            uint32_t w = 0, h = 0;
            if (!value(v) || !cli::parseSize(v, w, h, kMaxCompareSide))
                return usageError("--size takes " + cli::sizeRule(kMaxCompareSide));
            opts.width = w, opts.height = h;
        } else if (a == "--seed") {
            if (!value(v) || v.empty() || v.find_first_not_of("0123456789") != std::string::npos)
                return usageError("--seed takes a non-negative integer");
            opts.seed = std::stoull(v);
        } else if (a == "--random") {
            if (!value(v) || v.empty() || v.size() > 7 || v.find_first_not_of("0123456789") != std::string::npos)
                return usageError("--random takes a count 0..9999999");
            opts.random = std::stol(v);
        } else if (a == "--minor") {
            if (!value(v) || v.size() != 1 || v[0] < '1' || v[0] > '4') return usageError("--minor takes 1, 2, 3 or 4");
            opts.minor = v[0] - '0';
        } else if (a == "--out") {
            if (!value(opts.outDir)) return usageError("--out needs a folder");
        } else if (a == "--heatmap") {
            if (!value(opts.heatmap)) return usageError("--heatmap needs a PNG path");
        } else if (a == "--hardware") {
            if (!value(v)) return usageError("--hardware needs a class");
            opts.hardware = findHardware(v);
            if (!opts.hardware) return usageError(unknownHardwareMessage(v));
        } else if (a == "--precision") {
            if (!value(v)) return usageError("--precision needs a profile");
            opts.precision = parsePrecision(v);
            if (!opts.precision)
                return usageError("unknown precision " + quote(v) + " (expected fx8, fx12, float or ideal)");
        } else if (a == "--gl") {
            if (!value(glName) || (glName != "osmesa" && glName != "egl"))
                return usageError("--gl takes osmesa or egl");
        } else if (a == "--gl-mode") {
            if (!value(v) || (v != "exact" && v != "native")) return usageError("--gl-mode takes exact or native");
            opts.native = v == "native";
        } else if (!a.empty() && a[0] == '-') {
            return usageError(
                cli::unknownOption(a, {"--size", "--seed", "--random", "--minor", "--out", "--heatmap", "--hardware",
                                       "--precision", "--json", "--gl", "--gl-mode", "--gl-filtering", "--verbose", "--help"}));
        } else if (input.empty()) {
            input = a;
        } else {
            return usageError("one input at a time (got " + quote(input) + " and " + quote(a) + ")");
        }
    }
    if (opts.random < 0 && input.empty()) return usageError("missing SHADER.psh or FILE.ps11test (or --random N)");
    if (opts.random >= 0 && !input.empty()) return usageError("--random takes no input file");
    if (opts.random >= 0 && opts.native)
        return usageError("--random looks for disagreements of the exact mode; --gl-mode native does not apply");
    if (opts.native && opts.glFiltering) return usageError("--gl-filtering is an exact-mode option; native filters with GL");
    std::string error;
    const ps11test::RendererFactory gl = ps11test::glRendererFactory(glName, error, opts.native, opts.glFiltering);
    if (!gl) {
        std::cerr << "ps11 compare: " << error << "\n";
        return cli::kUserError;
    }
    if (opts.random >= 0) return runRandom(opts, gl);

    std::optional<std::string> text = cli::readFile(input);
    if (!text) return cli::kUserError;
    const bool testFile = input.size() > 9 && input.substr(input.size() - 9) == ".ps11test";
    if (!testFile) {
        text = shaderCase(*text, input, opts);
        if (!text) return cli::kUserError;
    }
    Report r;
    compareText(*text, input, opts, gl, r);
    if (!r.error.empty()) {
        std::cerr << r.error << (r.error.back() == '\n' ? "" : "\n");
        return cli::kUserError;
    }
    printReport(input, r, opts);
    if (!opts.heatmap.empty() && !r.draws.empty() && !writeHeatmap(opts.heatmap, r)) return cli::kUserError;
    if (opts.native) return r.error.empty() && r.unsupported.empty() ? cli::kOk : cli::kUserError;
    return r.agrees() ? cli::kOk : cli::kUserError;
}

}  // namespace ps11
