// `ps11 glare` and `ps11 shade` (tools/cmd_glare.h).
#include "tools/cmd_glare.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>

#include <unistd.h>

#include "emu/format.h"
#include "emu/fullscreen.h"
#include "emu/image_file.h"
#include "emu/thread_pool.h"
#include "glare/compare.h"
#include "glare/photos.h"
#include "glare/report.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "glare/shade.h"
#include "ps11/hardware.h"
#include "ps11/json_internal.h"
#include "tools/cli_util.h"
#include "runner/gl_backend.h"

namespace ps11 {

namespace {

constexpr const char* kGlareUsage =
    "usage: ps11 glare --list\n"
    "       ps11 glare --report [--json | --markdown]\n"
    "       ps11 glare --technique T (--scene S | --in IMG|DIR) [-o OUT.png] [--frames N] [--size WxH]\n"
    "                  [--backend emu|gl] [--gl osmesa|egl] [--gl-mode exact|native] [--hardware H | --precision P]\n"
    "                  [--quality low|medium|high|published] [--set name=value]... [--exposure STOPS]\n"
    "                  [--dump-passes DIR] [--graph OUT.dot] [--compare] [--json] [--no-skip]\n";

int glareUsage(const std::string& msg) {
    std::cerr << "ps11 glare: " << msg << "\n" << kGlareUsage;
    return cli::kUsage;
}

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

struct GlareOptions {
    bool list = false, report = false, markdown = false, json = false, compare = false;
    std::string technique, scene, in, out, dumpDir, graph;
    int frames = 1;
    uint32_t width = 0, height = 0;
    std::string backend = "emu", glKind;
    bool backendGiven = false;
    bool glNative = false, glModeGiven = false;  // --gl-mode
    const HardwareClass* hardware = nullptr;
    std::optional<Precision> precision;
    std::string quality = "published";
    std::vector<std::string> sets;
    float exposure = 0;
    bool noSkip = false;  // --no-skip: every pass runs every frame
};

std::string numbered(const std::string& path, int frame, int frames) {
    if (frames <= 1) return path;
    const std::filesystem::path p(path);
    char n[16];
    std::snprintf(n, sizeof n, "_%04d", frame);
    return (p.parent_path() / (p.stem().string() + n + p.extension().string())).string();
}

std::string safeName(const std::string& s) {
    std::string out;
    for (char c : s) out += (std::isalnum(uint8_t(c)) || c == '_' || c == '-') ? c : '_';
    return out;
}

// A grid of thumbnails (each fitted into 256x144, nearest sampling), in pass order.
emu::RgbaImage contactSheet(const std::vector<emu::RgbaImage>& images) {
    const uint32_t cw = 256, ch = 144, cols = 4, gap = 4;
    const uint32_t rows = uint32_t((images.size() + cols - 1) / cols);
    emu::RgbaImage sheet;
    sheet.width = cols * (cw + gap) + gap;
    sheet.height = std::max(rows, 1u) * (ch + gap) + gap;
    sheet.rgba.assign(size_t(sheet.width) * sheet.height * 4, 48);
    for (size_t k = 0; k < images.size(); ++k) {
        const emu::RgbaImage& im = images[k];
        const double scale = std::min(double(cw) / im.width, double(ch) / im.height);
        const uint32_t tw = std::max(1u, uint32_t(im.width * scale)), th = std::max(1u, uint32_t(im.height * scale));
        const uint32_t ox = gap + uint32_t(k % cols) * (cw + gap), oy = gap + uint32_t(k / cols) * (ch + gap);
        for (uint32_t y = 0; y < th; ++y)
            for (uint32_t x = 0; x < tw; ++x) {
                const uint32_t sx = std::min(im.width - 1, uint32_t(x / scale)), sy = std::min(im.height - 1, uint32_t(y / scale));
                const uint8_t* s = &im.rgba[(size_t(sy) * im.width + sx) * 4];
                uint8_t* d = &sheet.rgba[(size_t(oy + y) * sheet.width + ox + x) * 4];
                d[0] = s[0], d[1] = s[1], d[2] = s[2];
            }
    }
    for (size_t i = 3; i < sheet.rgba.size(); i += 4) sheet.rgba[i] = 255;
    return sheet;
}

int listTechniques() {
    for (const glare::Technique* t : glare::techniques()) {
        std::printf("%-8s %s\n         %s\n", std::string(t->name()).c_str(), std::string(t->title()).c_str(),
                    std::string(t->summary()).c_str());
        std::printf("         %-13s %-34s %s\n", "setting", "low / medium / high / published", "range");
        for (const glare::ParamInfo& p : t->params()) {
            std::string presets;
            for (double v : p.presets) presets += (presets.empty() ? "" : " / ") + glare::settingText(p, v);
            std::string range;
            if (!p.choices.empty())
                for (const std::string& c : p.choices) range += (range.empty() ? "" : "|") + c;
            else
                range = fmt("%g", p.min) + " .. " + fmt("%g", p.max) + (p.unit.empty() ? "" : " " + p.unit);
            std::printf("         %-13s %-34s %s\n", p.name.c_str(), presets.c_str(), range.c_str());
        }
        std::printf("\n");
    }
    std::printf("scenes (--scene):\n");
    for (const glare::SceneInfo& s : glare::sceneList())
        std::printf("  %-7s %s (%d frames by default)\n", std::string(s.name).c_str(), std::string(s.description).c_str(),
                    s.defaultFrames);
    return cli::kOk;
}

int report(const GlareOptions& o) {
    const glare::FitsReport r = glare::fitsReport();
    if (o.json) {
        std::cout << glare::fitsReportJson(r);
        return cli::kOk;
    }
    if (o.markdown) {
        std::cout << glare::fitsReportMarkdown(r);
        return cli::kOk;
    }
    std::printf("%-9s %-10s %-16s %-15s %-24s %-6s %-6s %-10s %s\n", "technique", "preset", "pass", "kind", "shader",
                "tex", "arith", "target", "fits ps_1_1");
    for (const glare::PassFit& f : r.passes) {
        const bool shader = f.kind == glare::PassKind::Shader;
        std::printf("%-9s %-10s %-16s %-15s %-24s %-6s %-6s %-10s %s\n", f.technique.c_str(), f.preset.c_str(),
                    f.pass.c_str(), glare::passKindName(f.kind), shader ? f.shader.c_str() : "-",
                    shader ? (std::to_string(f.texSlots) + "/" + std::to_string(f.texLimit)).c_str() : "-",
                    shader ? (std::to_string(f.arithSlots) + "/" + std::to_string(f.arithLimit)).c_str() : "-",
                    f.width ? (std::to_string(f.width) + "x" + std::to_string(f.height)).c_str() : "CPU",
                    f.fits ? "yes" : ("NO: " + f.note).c_str());
    }
    return cli::kOk;
}

class Progress {
public:
    // Only on a terminal: a log or a pipe gets no carriage-return lines.
    explicit Progress(int frames)
        : m_frames(frames), m_start(std::chrono::steady_clock::now()), m_terminal(isatty(2) != 0) {}
    ~Progress() {
        if (m_shown) std::fprintf(stderr, "\n");
    }
    bool shows() const { return m_terminal; }  // (only a terminal gets the progress line)
    void update(int frame, const std::string& pass) {
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
        if (!m_terminal || s < 1.0) return;
        m_shown = true;
        std::fprintf(stderr, "\rps11 glare: frame %d/%d, %-24s %6.1f s", frame + 1, m_frames, pass.c_str(), s);
        std::fflush(stderr);
    }

private:
    int m_frames;
    std::chrono::steady_clock::time_point m_start;
    bool m_terminal;
    bool m_shown = false;
};

int runGlare(const GlareOptions& o) {
    const glare::Technique* technique = glare::findTechnique(o.technique);
    if (!technique) return glareUsage(glare::unknownTechniqueMessage(o.technique));
    std::optional<glare::Settings> settings = glare::presetSettings(*technique, o.quality);
    if (!settings) return glareUsage("unknown --quality '" + o.quality + "' (low, medium, high, published)");
    for (const std::string& s : o.sets) {
        std::string err;
        if (!glare::applySetting(*technique, *settings, s, err)) return glareUsage(err);
    }

    // The input: an image file (its size) or a scene (--size, 1920x1080 by default).
    std::optional<emu::FloatImage> image;
    std::unique_ptr<glare::Scene> scene;
    uint32_t width = o.width, height = o.height;
    if (!o.in.empty()) {
        std::string err;
        std::optional<emu::LoadedImage> loaded = emu::readImage(o.in, err);
        if (!loaded) {
            std::cerr << "ps11 glare: " << err << "\n";
            return cli::kUserError;
        }
        image = loaded->hdr ? emu::exposeUnclamped(loaded->image, o.exposure) : loaded->image;
        width = image->width;
        height = image->height;
    } else {
        std::string err;
        scene = glare::makeScene(o.scene, err);
        if (!scene) return glareUsage(err);
        if (!width) width = 1920, height = 1080;
    }
    if (width < 8 || height < 8) {
        std::cerr << "ps11 glare: the frame is " << width << "x" << height << "; the techniques need at least 8x8\n";
        return cli::kUserError;
    }

    auto makeRunner = [&](bool gl, std::string& err) -> std::unique_ptr<glare::Runner> {
        glare::RunnerOptions ro;
        ro.width = width;
        ro.height = height;
        ro.device.hardware = o.hardware;
        ro.device.precision = o.precision;
        ro.skip = !o.noSkip;
        ro.graphviz = !o.graph.empty();
        if (gl) {
            ro.device.renderer = ps11test::glRendererFactory(o.glKind, err, o.glNative);
            if (!ro.device.renderer) return nullptr;
        }
        return std::make_unique<glare::Runner>(ro);
    };
    std::string err;
    std::unique_ptr<glare::Runner> main = makeRunner(o.backend == "gl" && !o.compare, err);
    std::unique_ptr<glare::Runner> other;
    if (!main || (o.compare && !(other = makeRunner(true, err)))) {
        std::cerr << "ps11 glare: the GL renderer is not available: " << err << "\n";
        return cli::kUserError;
    }
    // --compare --gl-mode native, end to end: whole frames on GL native (not pass-isolated) and
    // under `ideal` on the emulator, from the same input as the emulated card's.
    std::unique_ptr<glare::Runner> ideal, nativeRun;
    if (o.compare && o.glNative) {
        glare::RunnerOptions ro;
        ro.width = width;
        ro.height = height;
        ro.device.hardware = o.hardware;
        ro.device.precision = Precision::Ideal;
        ro.skip = !o.noSkip;
        ideal = std::make_unique<glare::Runner>(ro);
        nativeRun = makeRunner(true, err);
        for (glare::Runner* r : {ideal.get(), nativeRun.get()})
            if (!r || (image && !r->setImage(*image, err))) {
                std::cerr << "ps11 glare: " << o.in << ": " << err << "\n";
                return cli::kUserError;
            }
    }

    // --graph without -o: the graph as built, not run.
    if (!o.graph.empty() && o.out.empty() && !o.compare && o.dumpDir.empty()) {
        glare::PassGraph g;
        main->buildFrame(*technique, *settings, 0, o.frames, g);
        return cli::writeFile(o.graph, g.graphviz(std::string(technique->name()))) ? cli::kOk : cli::kUserError;
    }

    if (image && !main->setImage(*image, err)) {
        std::cerr << "ps11 glare: " << o.in << ": " << err << "\n";
        return cli::kUserError;
    }
    if (image && other && !other->setImage(*image, err)) {
        std::cerr << "ps11 glare: " << o.in << ": " << err << "\n";
        return cli::kUserError;
    }
    if (!o.dumpDir.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(o.dumpDir, ec);
        if (ec) {
            std::cerr << "ps11 glare: cannot create " << o.dumpDir << ": " << ec.message() << "\n";
            return cli::kUserError;
        }
    }

    std::unique_ptr<glare::Scene> otherScene;  // the scene's resources on the GL device
    if (scene && other && !(otherScene = glare::makeScene(o.scene, err))) return glareUsage(err);
    const auto [fogStart, fogEnd] = technique->sceneGlowFog(*settings);
    for (glare::Scene* s : {scene.get(), otherScene.get()})
        if (s) s->setGlowFog(fogStart, fogEnd);
    Progress progress(o.frames);
    std::vector<glare::PassStats> lastStats;
    // Each pass's time in every frame that ran it (not reused), by name: the table's medians.
    std::map<std::string, std::vector<double>> passMs;
    double lastBuildMs = 0;  // the last frame's graph, built and compiled
    bool lastStill = false;  // the last frame was skipped whole
    emu::RgbaImage frameImage;  // -o: each frame's output, read into one buffer
    std::vector<double> frameMs;
    emu::TransferStats lastTransfers;  // the last frame's, with its output's read-back
    std::vector<glare::PassAgreement> agreement;
    glare::PassAgreement sceneAgreement{"scene (rendered on both)"};
    for (int f = 0; f < o.frames; ++f) {
        double sceneMs = 0;
        if (scene) {
            if (!main->renderScene(*scene, f, o.frames, sceneMs, err)) {
                std::cerr << "ps11 glare: " << err << "\n";
                return cli::kUserError;
            }
            if (other) {
                // The scene drawn on GL too (compared), then the emulator's frame handed over so both
                // techniques start from the same pixels.
                double ms = 0;
                emu::Handle ms1{}, gs1{};
                main->device().GetSurfaceLevel(main->sceneTexture(), 0, &ms1);
                other->device().GetSurfaceLevel(other->sceneTexture(), 0, &gs1);
                if (!other->renderScene(*otherScene, f, o.frames, ms, err)) {
                    std::cerr << "ps11 glare: GL: " << err << "\n";
                    return cli::kUserError;
                }
                std::optional<emu::SurfacePixels> a = emu::readSurface(main->device(), ms1, err);
                std::optional<emu::SurfacePixels> b = a ? emu::readSurface(other->device(), gs1, err) : std::nullopt;
                if (!a || !b || !emu::writeSurface(other->device(), gs1, *a, err)) {
                    std::cerr << "ps11 glare: " << err << "\n";
                    return cli::kUserError;
                }
                glare::accumulate(sceneAgreement, *a, *b);
            }
        }
        // Hooks: progress and the last frame's dumps (the cross-check captures in glare/compare.cpp).
        const bool dump = !o.dumpDir.empty() && f == o.frames - 1;
        std::vector<emu::RgbaImage> sheet;
        auto hook = [&](glare::PassGraph& g, uint32_t pass, bool after, std::string& e) {
            const glare::PassGraph::PassNode& n = g.passes()[pass];
            progress.update(f, n.info.name);
            if (after && dump)
                for (glare::TextureId id : n.writes) {
                    if (g.texture(id).data) continue;
                    std::optional<emu::RgbaImage> img = main->readTexture(g.texture(id).device, e);
                    if (!img) return false;
                    char prefix[16];
                    std::snprintf(prefix, sizeof prefix, "%02u_", pass);
                    const std::string path = o.dumpDir + "/" + prefix + safeName(n.info.name) + "-" +
                                             safeName(g.texture(id).name) + ".png";
                    if (!emu::writePng(path, emu::opaque(*img), e)) return false;
                    sheet.push_back(emu::opaque(*img));
                }
            return true;
        };
        glare::FrameResult result;
        bool ok;
        const emu::TransferStats before = main->device().transfers();
        if (other) {
            ok = glare::compareFrame(*main, *other, *technique, *settings, f, o.frames, agreement, result, err, hook);
            if (ok && ideal) {
                std::optional<emu::RgbaImage> input = scene ? main->readTexture(main->sceneTexture(), err) : std::nullopt;
                for (glare::Runner* r : {ideal.get(), nativeRun.get()}) {
                    glare::FrameResult ir;
                    ok = ok && (!scene || (input && r->setImage(*input, err))) &&
                         r->runFrame(*technique, *settings, f, o.frames, ir, err);
                }
            }
        } else if (dump || progress.shows()) {
            glare::PassGraph* built = nullptr;
            ok = main->runFrame(
                *technique, *settings, f, o.frames, result, err,
                [&](uint32_t pass, bool after, std::string& e) { return hook(*built, pass, after, e); },
                [&](glare::PassGraph& g) { built = &g; }, true);  // progress and dumps only look
        } else {
            // No hook: a still input's frames after the first ones may be skipped whole (FrameResult::still).
            ok = main->runFrame(*technique, *settings, f, o.frames, result, err);
        }
        if (!ok) {
            std::cerr << "ps11 glare: " << err << "\n";
            return cli::kUserError;
        }
        if (f == 0 && !o.graph.empty() && !cli::writeFile(o.graph, main->lastGraphviz())) return cli::kUserError;
        if (dump && !emu::writePng(o.dumpDir + "/contact_sheet.png", contactSheet(sheet), err)) {
            std::cerr << "ps11 glare: " << err << "\n";
            return cli::kUserError;
        }
        lastStats = result.passes;
        for (const glare::PassStats& ps : result.passes)
            if (!ps.reused) passMs[ps.pass].push_back(ps.milliseconds);
        lastBuildMs = result.buildMilliseconds;
        lastStill = result.still;
        frameMs.push_back(result.milliseconds);
        if (!o.out.empty()) {
            // One image for every frame: no 8 MB allocated and given back per 1080p frame.
            bool written = main->readOutput(frameImage, err);
            if (written) {
                emu::makeOpaque(frameImage);
                written = emu::writePng(numbered(o.out, f, o.frames), frameImage, err);
            }
            if (!written) {
                std::cerr << "ps11 glare: " << err << "\n";
                return cli::kUserError;
            }
        }
        const emu::TransferStats after = main->device().transfers();
        lastTransfers.uploads = after.uploads - before.uploads;
        lastTransfers.readBacks = after.readBacks - before.readBacks;
    }

    const std::string profile = precisionName(main->device().hardware().precision);
    const std::string hw(main->device().hardware().hardware->name);
    if (o.compare) {
        uint64_t over = sceneAgreement.overOne;
        for (const glare::PassAgreement& a : agreement) over += a.overOne;
        // Native mode, end to end (the last frame's output): GL against the card and against ideal.
        glare::ImageError vsCard, vsIdeal;
        if (ideal) {
            std::optional<emu::RgbaImage> a = main->readOutput(err), g = a ? nativeRun->readOutput(err) : std::nullopt,
                                          i = g ? ideal->readOutput(err) : std::nullopt;
            if (!i) {
                std::cerr << "ps11 glare: " << err << "\n";
                return cli::kUserError;
            }
            vsCard = glare::imageError(*g, *a);
            vsIdeal = glare::imageError(*g, *i);
        }
        auto errorJson = [](const glare::ImageError& e) {
            return json::Json{{"max_levels", e.max},
                              {"mean_levels", json::rounded(e.mean, "%.4f")},
                              {"over_one_pct", json::rounded(e.overOnePercent, "%.4f")}};
        };
        if (o.json) {
            json::Json j;
            j["technique"] = std::string(technique->name());
            j["hardware"] = hw;
            j["profile"] = profile;
            j["gl"] = ps11test::glRendererDescription();
            j["frames"] = o.frames;
            std::vector<glare::PassAgreement> all;
            if (scene) all.push_back(sceneAgreement);
            all.insert(all.end(), agreement.begin(), agreement.end());
            json::Json passes = json::Json::array();
            for (const glare::PassAgreement& a : all)
                passes.push_back({{"pass", a.pass},
                                  {"pixels", a.pixels},
                                  {"exact", a.exact},
                                  {"over_one", a.overOne},
                                  {"max_diff", json::rounded(a.maxDiff, "%g")}});
            j["passes"] = std::move(passes);
            j["gl_mode"] = o.glNative ? "native" : "exact";
            if (ideal) j["end_to_end"] = {{"vs_card", errorJson(vsCard)}, {"vs_ideal", errorJson(vsIdeal)}};
            std::cout << json::dump(j, 2) << "\n";
        } else {
            std::printf("%s on %ux%u, %d frame(s), %s / %s: the emulator against %s, pass-isolated\n",
                        std::string(technique->name()).c_str(), width, height, o.frames, hw.c_str(), profile.c_str(),
                        ps11test::glRendererDescription().c_str());
            std::printf("%-26s %12s %9s %10s %9s\n", "pass", "pixels", "exact", "|d|>1", "max |d|");
            auto row = [](const glare::PassAgreement& a) {
                if (a.pixels == 0) {  // a device-side step: no texture to compare
                    std::printf("%-26s %12s %9s %10s %9s\n", a.pass.c_str(), "0", "-", "-", "-");
                    return;
                }
                std::printf("%-26s %12llu %8.3f%% %10llu %9.3g\n", a.pass.c_str(), (unsigned long long)a.pixels,
                            100.0 * double(a.exact) / double(a.pixels), (unsigned long long)a.overOne, a.maxDiff);
            };
            if (scene) row(sceneAgreement);
            for (const glare::PassAgreement& a : agreement) row(a);
            if (ideal) {
                std::printf("gl native mode: measured, not checked (a GPU's float arithmetic, filtering and blending)\n");
                std::printf("end to end, last frame: gl native against the emulated card: max %d levels, mean %.3f, %.3f %% "
                            "of pixels more than one level apart\n",
                            vsCard.max, vsCard.mean, vsCard.overOnePercent);
                std::printf("end to end, last frame: gl native against ideal: max %d levels, mean %.3f, %.3f %% of pixels "
                            "more than one level apart\n",
                            vsIdeal.max, vsIdeal.mean, vsIdeal.overOnePercent);
            } else {
                std::printf("%s\n", over == 0 ? "agreement: every pass within 1 level"
                                              : "DISAGREEMENT: pixels differ by more than 1 level");
            }
        }
        if (ideal) return cli::kOk;
        return over == 0 ? cli::kOk : cli::kUserError;
    }
    // The host's memory speed, measured now, after the frames: what the MB column's passes would
    // reach if moving their bytes were all they did.
    const glare::Runner::CopySpeed copy = main->copySpeed();
    // A pass's median time over the frames that ran it (0 when none did), and how many did.
    auto medianOf = [&](const std::string& pass) -> std::pair<double, size_t> {
        auto it = passMs.find(pass);
        if (it == passMs.end() || it->second.empty()) return {0.0, 0};
        std::vector<double> v = it->second;
        std::sort(v.begin(), v.end());
        return {v[v.size() / 2], v.size()};
    };
    if (o.json) {
        json::Json j;
        j["technique"] = std::string(technique->name());
        j["hardware"] = hw;
        j["profile"] = profile;
        j["size"] = {width, height};
        j["frames"] = o.frames;
        json::Json passes = json::Json::array();
        for (const glare::PassStats& s : lastStats)
            passes.push_back({{"pass", s.pass},
                              {"ms", json::rounded(s.milliseconds, "%.3f")},
                              {"median_ms", json::rounded(medianOf(s.pass).first, "%.3f")},
                              {"frames_run", medianOf(s.pass).second},
                              {"draws", s.draws},
                              {"pixels", s.pixels},
                              {"texels", s.texels},
                              {"instructions", s.instructions},
                              {"uploads", s.uploads},
                              {"readbacks", s.readBacks},
                              {"bytes", s.bytes},
                              {"reused", s.reused},
                              {"put_off", s.putOff},
                              {"tiles",
                               {{"shaded", s.tilesShaded},
                                {"filled", s.tilesFilled},
                                {"copied", s.tilesCopied},
                                {"skipped", s.tilesSkipped}}}});
        j["passes"] = std::move(passes);
        j["graph_ms"] = json::rounded(lastBuildMs, "%.3f");
        j["still"] = lastStill;
        j["renderer"] = main->device().rendererName();
        j["copy_gbps"] = {{"warm", json::rounded(copy.warm, "%.1f")}, {"cold", json::rounded(copy.cold, "%.1f")}};
        j["frame_uploads"] = lastTransfers.uploads;
        j["frame_readbacks"] = lastTransfers.readBacks;
        std::cout << json::dump(j, 2) << "\n";
        return cli::kOk;
    }
    std::vector<double> sorted = frameMs;
    std::sort(sorted.begin(), sorted.end());
    std::printf("%s on %ux%u (%s), %s / %s, %s renderer, %d frame(s): median %.2f ms per frame\n",
                std::string(technique->name()).c_str(), width, height, scene ? ("scene " + o.scene).c_str() : o.in.c_str(),
                hw.c_str(), profile.c_str(), main->device().rendererName(), o.frames, sorted[sorted.size() / 2]);
    std::printf("%-22s %9s %9s %6s %11s %11s %13s %4s %4s %8s %7s  %-6s %s\n", "pass (last frame)", "ms", "median",
                "draws", "pixels", "texels", "instructions", "up", "back", "MB", "GB/s", "run",
                "tiles shaded/filled/copied/skipped");
    for (const glare::PassStats& s : lastStats) {
        const auto [median, ran] = medianOf(s.pass);
        char medianText[16] = "-";
        if (ran) std::snprintf(medianText, sizeof medianText, "%.3f", median);
        if (s.reused) {
            std::printf("%-22s %9.3f %9s %6s %11s %11s %13s %4s %4s %8s %7s  reused -\n", s.pass.c_str(),
                        s.milliseconds, medianText, "-", "-", "-", "-", "-", "-", "-", "-");
            continue;
        }
        const uint64_t tiles = s.tilesShaded + s.tilesFilled + s.tilesCopied + s.tilesSkipped;
        const std::string tileText = tiles ? std::to_string(s.tilesShaded) + "/" + std::to_string(s.tilesFilled) + "/" +
                                                 std::to_string(s.tilesCopied) + "/" + std::to_string(s.tilesSkipped)
                                           : "-";
        char gbps[16] = "-";  // a copy put off moved nothing in its own time
        if (!s.putOff && median > 0) std::snprintf(gbps, sizeof gbps, "%.1f", double(s.bytes) / 1e6 / median);
        std::printf("%-22s %9.3f %9s %6llu %11llu %11llu %13llu %4llu %4llu %8.2f %7s  %-6s %s\n", s.pass.c_str(),
                    s.milliseconds, medianText, (unsigned long long)s.draws, (unsigned long long)s.pixels,
                    (unsigned long long)s.texels, (unsigned long long)s.instructions, (unsigned long long)s.uploads,
                    (unsigned long long)s.readBacks, double(s.bytes) / 1e6, gbps, s.putOff ? "put off" : "ran",
                    tileText.c_str());
    }
    std::printf("%-22s %9.3f  (the technique's graph, built and compiled on the CPU; part of the frame's time)\n",
                "(frame graph)", lastBuildMs);
    uint64_t frameBytes = 0;
    for (const glare::PassStats& s : lastStats) frameBytes += s.reused ? 0 : s.bytes;
    auto floorMs = [&](double gbps) { return gbps > 0 ? double(frameBytes) / 1e6 / gbps : 0.0; };
    std::printf("(this host now: a %ux%u RGBA8 copy on %d thread(s) moves %.1f GB/s from the cache and %.1f from memory,\n"
                " read and written counted as MB is: the last frame's %.2f MB would take %.3f to %.3f ms)\n",
                width, height, main->cpuPool().size(), copy.warm, copy.cold, double(frameBytes) / 1e6,
                floorMs(copy.warm), floorMs(copy.cold));
    if (lastStill)
        std::printf("(the last frame was skipped whole: a still input whose frame before reused every pass; nothing was\n"
                    " built or run)\n");
    std::printf(
        "(ms: the last frame's; median: over the frames that ran the pass, not reused (with -o each frame's PNG\n"
        " is written between frames, so the passes start from caches it evicted))\n");
    std::printf(
        "(MB: what each pass must move at least, every texture it reads and writes once; GB/s: that over its median;\n"
        " reused: its inputs were last frame's, its outputs kept, nothing ran; put off: a whole-surface copy the\n"
        " software renderer makes in the pass that next draws into, reads or writes its destination, in whose\n"
        " time it then is (the composite copies each band of the scene just before it blends onto it, or\n"
        " blends onto the scene's words as it writes the target's);\n"
        " tiles: tiles of 16 rows by 64 pixels of the software renderer's full-screen draws, shaded, filled\n"
        " with a constant, copied from one texture or skipped, as the interval evaluator decided; -: none\n"
        " decided (no such draw, or deciding did not pay on the program's recent draws); --no-skip runs every\n"
        " pass and draws every tile)\n");
    if (o.backend == "gl")
        std::printf("surfaces crossing between the device and the %s renderer in the last frame: %llu uploaded, %llu read "
                    "back%s\n",
                    main->device().rendererName(), (unsigned long long)lastTransfers.uploads,
                    (unsigned long long)lastTransfers.readBacks, o.out.empty() ? "" : " (the output's read-back included)");
    if (!o.out.empty())
        std::printf("wrote %s\n", o.frames > 1 ? (numbered(o.out, 0, o.frames) + " …").c_str() : o.out.c_str());
    return cli::kOk;
}

// `path` with `_tag` before its extension: out.png -> out_city.png.
std::string tagged(const std::string& path, const std::string& tag) {
    const std::filesystem::path p(path);
    return (p.parent_path() / (p.stem().string() + "_" + tag + p.extension().string())).string();
}

// `--in DIR`: every image file of the folder in turn (glare::imageFilesIn: *.png, *.hdr, *.exr, sorted),
// each run as `--in FILE` with its outputs named after the image: -o OUT.png -> OUT_<stem>.png,
// --dump-passes D -> D/<stem>/, --graph G.dot -> G_<stem>.dot (<stem>_<ext> where two files share a stem).
// Text output: a "== FILE" line before each image's; --json: an array of each image's object. The first
// image that fails stops the run with its status.
int runGlareFolder(const GlareOptions& o) {
    std::string err;
    std::optional<std::vector<std::string>> files = glare::imageFilesIn(o.in, err);
    if (!files) {
        std::cerr << "ps11 glare: " << err << "\n";
        return cli::kUserError;
    }
    if (files->empty()) {
        std::cerr << "ps11 glare: " << o.in << ": no image files (*.png, *.hdr, *.exr) in the folder\n";
        return cli::kUserError;
    }
    std::map<std::string, int> stems;
    for (const std::string& f : *files) ++stems[std::filesystem::path(f).stem().string()];
    if (o.json) std::printf("[\n");
    for (size_t i = 0; i < files->size(); ++i) {
        const std::filesystem::path file((*files)[i]);
        std::string tag = safeName(file.stem().string());
        if (stems[file.stem().string()] > 1) tag += "_" + safeName(file.extension().string().substr(1));
        GlareOptions each = o;
        each.in = file.string();
        if (!o.out.empty()) each.out = tagged(o.out, tag);
        if (!o.dumpDir.empty()) each.dumpDir = (std::filesystem::path(o.dumpDir) / tag).string();
        if (!o.graph.empty()) each.graph = tagged(o.graph, tag);
        if (o.json && i) std::printf(",\n");
        if (!o.json) std::printf("== %s (%zu of %zu)\n", each.in.c_str(), i + 1, files->size());
        std::fflush(stdout);
        const int status = runGlare(each);
        std::fflush(stdout);
        if (status != cli::kOk) {
            if (o.json) std::printf("]\n");
            return status;
        }
    }
    if (o.json) std::printf("]\n");
    return cli::kOk;
}

}  // namespace

int cmdGlare(const std::vector<std::string>& args) {
    GlareOptions o;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&](std::string& out) {
            if (i + 1 >= args.size()) return false;
            out = args[++i];
            return true;
        };
        std::string v;
        if (a == "--help" || a == "-h") {
            std::cout << kGlareUsage;
            return cli::kOk;
        } else if (a == "--list") {
            o.list = true;
        } else if (a == "--report") {
            o.report = true;
        } else if (a == "--markdown") {
            o.markdown = true;
        } else if (a == "--json") {
            o.json = true;
        } else if (a == "--compare") {
            o.compare = true;
        } else if (a == "--technique" || a == "-t") {
            if (!value(o.technique)) return glareUsage("--technique needs a name");
        } else if (a == "--scene") {
            if (!value(o.scene)) return glareUsage("--scene needs a name");
        } else if (a == "--in") {
            if (!value(o.in)) return glareUsage("--in needs an image file or a folder of them");
        } else if (a == "-o" || a == "--out") {
            if (!value(o.out)) return glareUsage("-o needs a file name");
        } else if (a == "--dump-passes") {
            if (!value(o.dumpDir)) return glareUsage("--dump-passes needs a folder");
        } else if (a == "--graph") {
            if (!value(o.graph)) return glareUsage("--graph needs a file name");
        } else if (a == "--frames") {
            if (!value(v) || !cli::parseCount(v, 1, 99999, o.frames)) return glareUsage("--frames takes a count 1..99999");
        } else if (a == "--size") {
            if (!value(v) || !cli::parseSize(v, o.width, o.height)) return glareUsage("--size takes " + cli::sizeRule());
        } else if (a == "--backend") {
            if (!value(o.backend) || (o.backend != "emu" && o.backend != "gl"))
                return glareUsage("--backend takes emu or gl");
            o.backendGiven = true;
        } else if (a == "--gl") {
            if (!value(o.glKind) || (o.glKind != "osmesa" && o.glKind != "egl")) return glareUsage("--gl takes osmesa or egl");
        } else if (a == "--gl-mode") {
            if (!value(v) || (v != "exact" && v != "native")) return glareUsage("--gl-mode takes exact or native");
            o.glNative = v == "native";
            o.glModeGiven = true;
        } else if (a == "--hardware") {
            if (!value(v)) return glareUsage("--hardware needs a class");
            o.hardware = findHardware(v);
            if (!o.hardware) return glareUsage(unknownHardwareMessage(v));
        } else if (a == "--precision") {
            if (!value(v)) return glareUsage("--precision needs a profile");
            o.precision = parsePrecision(v);
            if (!o.precision) return glareUsage("unknown precision '" + v + "' (expected fx8, fx12, float or ideal)");
        } else if (a == "--quality") {
            if (!value(o.quality)) return glareUsage("--quality needs low, medium, high or published");
        } else if (a == "--set") {
            if (!value(v)) return glareUsage("--set needs name=value");
            o.sets.push_back(v);
        } else if (a == "--no-skip") {
            o.noSkip = true;
        } else if (a == "--exposure") {
            char* end = nullptr;
            if (!value(v)) return glareUsage("--exposure needs a number of stops");
            o.exposure = std::strtof(v.c_str(), &end);
            if (end == v.c_str() || *end || !std::isfinite(o.exposure) || std::fabs(o.exposure) > 64)
                return glareUsage("--exposure takes stops in -64 .. 64");
        } else {
            return glareUsage(cli::unknownOption(
                a, {"--list", "--report", "--markdown", "--json", "--compare", "--technique", "--scene", "--in", "-o",
                    "--dump-passes", "--graph", "--frames", "--size", "--backend", "--gl", "--gl-mode", "--hardware", "--precision",
                    "--quality", "--set", "--exposure", "--no-skip", "--help"}));
        }
    }
    if (o.list) return listTechniques();
    if (o.report) return report(o);
    if (o.technique.empty()) return glareUsage("say which technique (--technique T), or --list, or --report");
    if (o.scene.empty() == o.in.empty()) return glareUsage("give one input: --scene NAME or --in IMAGE");
    if (!o.in.empty() && o.width) return glareUsage("--size applies to --scene; an --in image keeps its own size");
    if (o.hardware && o.precision) return glareUsage("give --hardware or --precision, not both");
    if (o.compare && o.backendGiven) return glareUsage("--compare runs both renderers; --backend does not apply");
    if (o.glModeGiven && o.backend != "gl" && !o.compare) return glareUsage("--gl-mode needs --backend gl or --compare");
    if (o.out.empty() && o.graph.empty() && o.dumpDir.empty() && !o.compare)
        return glareUsage("say where the result goes: -o OUT.png (or --dump-passes, --graph, --compare)");
    std::error_code ec;
    if (!o.in.empty() && std::filesystem::is_directory(o.in, ec)) return runGlareFolder(o);
    return runGlare(o);
}

}  // namespace ps11
