#include "tools/cmd_demo.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <vector>

#include "emu/image_file.h"
#include "glare/report.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "tools/cli_util.h"

namespace ps11 {

namespace {

}  // namespace

int runGlareDemo(const GlareDemoOptions& o) {
    std::error_code ec;
    std::filesystem::create_directories(o.outDir, ec);
    if (ec) {
        std::fprintf(stderr, "ps11: demo: cannot create %s: %s\n", o.outDir.c_str(), ec.message().c_str());
        return cli::kUserError;
    }
    const HardwareClass& cls = o.hardware ? *o.hardware : *resolveHardware(nullptr, 1, std::nullopt, 0).hardware;
    std::printf("The five glare techniques, each on its scene at %ux%u, published settings; emulated on %s (%s) and\n"
                "under the ideal profile (float, no clamping), the reference the error is measured against.\n"
                "Times are the technique's passes per frame on the emulator (median of %d frames, %s threads).\n\n",
                o.width, o.height, std::string(cls.name).c_str(), precisionName(cls.precision), std::max(o.repeats, 1),
                o.threads ? std::to_string(o.threads).c_str() : "all");
    std::printf("%-9s %-7s %7s %11s %11s %9s %10s %11s\n", "technique", "scene", "passes", "emulated", "ideal", "max err",
                "mean err", "err > 1");
    for (const glare::Technique* t : glare::techniques()) {
        const std::string name(t->name()), sceneName(t->scene());
        std::string err;
        glare::RunnerOptions ro;
        ro.width = o.width;
        ro.height = o.height;
        ro.device.hardware = &cls;
        ro.device.software.threads = o.threads;
        const glare::SceneRun fx = glare::runOnScene(*t, ro, o.repeats, err);
        ro.device.precision = Precision::Ideal;
        const glare::SceneRun ideal = fx.image ? glare::runOnScene(*t, ro, o.repeats, err) : glare::SceneRun{};
        if (!fx.image || !ideal.image) {
            std::fprintf(stderr, "ps11: demo: %s: %s\n", name.c_str(), err.c_str());
            return cli::kUserError;
        }
        const glare::ImageError e = glare::imageError(*fx.image, *ideal.image);
        std::printf("%-9s %-7s %7zu %9.2fms %9.2fms %9d %10.3f %10.2f%%\n", name.c_str(), sceneName.c_str(), fx.passes,
                    fx.medianMs, ideal.medianMs, e.max, e.mean, e.overOnePercent);
        for (const auto& [suffix, run] : {std::pair<const char*, const glare::SceneRun*>{"emulated", &fx}, {"ideal", &ideal}}) {
            const std::string path = o.outDir + "/" + name + "-" + sceneName + "-" + suffix + ".png";
            if (!emu::writePng(path, *run->image, err)) {
                std::fprintf(stderr, "ps11: demo: %s\n", err.c_str());
                return cli::kUserError;
            }
        }
    }
    std::printf("\n(err: the emulated image against ideal in 8-bit levels, over RGB; images in %s/)\n\n", o.outDir.c_str());

    // Fits ps_1_1: the published preset's passes.
    const glare::FitsReport report = glare::fitsReport();
    std::printf("Fits ps_1_1 (published settings at %ux%u; every preset in docs/fits-ps11.md, `ps11 glare --report`):\n",
                report.width, report.height);
    std::printf("%-9s %7s %8s %9s %11s %7s %11s  %s\n", "technique", "passes", "shaders", "max tex", "max arith",
                "fixed", "StretchRect", "needs more than 1.1");
    for (const glare::Technique* t : glare::techniques()) {
        int passes = 0, shaders = 0, fixed = 0, blits = 0, maxTex = 0, maxArith = 0;
        std::string beyond;
        for (const glare::PassFit& f : report.passes) {
            if (f.technique != t->name() || f.preset != "published") continue;
            ++passes;
            shaders += f.kind == glare::PassKind::Shader;
            fixed += f.kind == glare::PassKind::FixedFunction;
            blits += f.kind == glare::PassKind::StretchRect;
            maxTex = std::max(maxTex, f.texSlots);
            maxArith = std::max(maxArith, f.arithSlots);
            if (!f.fits) beyond += (beyond.empty() ? "" : "; ") + f.pass + ": " + f.note;
        }
        std::printf("%-9s %7d %8d %7d/4 %9d/8 %7d %11d  %s\n", std::string(t->name()).c_str(), passes, shaders, maxTex,
                    maxArith, fixed, blits, beyond.empty() ? "nothing" : beyond.c_str());
    }
    return cli::kOk;
}

}  // namespace ps11
