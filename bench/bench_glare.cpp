// BM_Glare: every glare technique (published settings) on a 1920×1080 frame of its scene, on the
// emulator (software renderer, 2 worker threads unless PS11_THREADS says otherwise) and on its
// peer, the GL renderer (Mesa llvmpipe through OSMesa, or EGL with PS11_GL=egl), in one process,
// frames interleaved emu, gl, emu, gl … under the same machine load. Before timing, one frame of
// each is compared pass by pass (glare/compare.h) and the emulated image against the ideal
// profile's; the counters report the agreement and the fx8-vs-ideal error. The reported time is
// the emulator's frame (the passes' own time); `gl_ms` and `gl_over_emu` are the peer's.
// How to run and read it: bench/README.md "bench_glare".
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "glare/compare.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "tools/gl_backend.h"

namespace {

constexpr uint32_t kW = 1920, kH = 1080;

int threads() {
    const char* t = std::getenv("PS11_THREADS");
    return t ? std::atoi(t) : 2;
}

std::unique_ptr<glare::Runner> makeRunner(bool gl, std::optional<ps11::Precision> p, std::string& err) {
    glare::RunnerOptions ro;
    ro.width = kW;
    ro.height = kH;
    ro.device.precision = p;
    ro.device.software.threads = threads();
    if (gl) {
        const char* kind = std::getenv("PS11_GL");
        ro.device.renderer = ps11::glRendererFactory(kind ? kind : "osmesa", err);
        if (!ro.device.renderer) return nullptr;
    }
    return std::make_unique<glare::Runner>(ro);
}

void BM_Glare(benchmark::State& state, const std::string& name) {
    const glare::Technique& t = *glare::findTechnique(name);
    const glare::Settings s = *glare::presetSettings(t, "published");
    std::string err;
    auto emuRun = makeRunner(false, std::nullopt, err);
    auto glRun = makeRunner(true, std::nullopt, err);
    auto idealRun = makeRunner(false, ps11::Precision::Ideal, err);
    if (!glRun) {
        state.SkipWithError(("no GL renderer: " + err).c_str());
        return;
    }
    std::unique_ptr<glare::Scene> scene = glare::makeScene(t.scene(), err);
    double ms = 0;
    std::optional<emu::RgbaImage> frame;
    if (!emuRun->renderScene(*scene, 0, 8, ms, err) || !(frame = emuRun->readTexture(emuRun->sceneTexture(), err)) ||
        !glRun->setImage(*frame, err) || !idealRun->setImage(*frame, err)) {
        state.SkipWithError(err.c_str());
        return;
    }
    // Agreement, pass-isolated, and the error against ideal (frame 0 each).
    std::vector<glare::PassAgreement> agreement;
    glare::FrameResult r;
    if (!glare::compareFrame(*emuRun, *glRun, t, s, 0, 2, agreement, r, err) || !idealRun->runFrame(t, s, 0, 2, r, err)) {
        state.SkipWithError(err.c_str());
        return;
    }
    uint64_t pixels = 0, exact = 0;
    for (const glare::PassAgreement& a : agreement) pixels += a.pixels, exact += a.exact;
    std::optional<emu::RgbaImage> a = emuRun->readOutput(err), b = idealRun->readOutput(err);
    double maxErr = 0, sumErr = 0;
    for (size_t i = 0; i < a->rgba.size(); ++i) {
        if (i % 4 == 3) continue;
        const double e = std::abs(int(a->rgba[i]) - int(b->rgba[i]));
        maxErr = std::max(maxErr, e);
        sumErr += e;
    }
    std::vector<double> emuMs, glMs;
    int f = 1;
    for (auto _ : state) {
        glare::FrameResult er, gr;
        if (!emuRun->runFrame(t, s, f, f + 1, er, err) || !glRun->runFrame(t, s, f, f + 1, gr, err)) {
            state.SkipWithError(err.c_str());
            return;
        }
        ++f;
        emuMs.push_back(er.milliseconds);
        glMs.push_back(gr.milliseconds);
        state.SetIterationTime(er.milliseconds / 1000);
    }
    std::sort(emuMs.begin(), emuMs.end());
    std::sort(glMs.begin(), glMs.end());
    const double em = emuMs[emuMs.size() / 2], gm = glMs[glMs.size() / 2];
    state.counters["emu_ms"] = em;
    state.counters["gl_ms"] = gm;
    state.counters["gl_over_emu"] = gm / em;
    state.counters["exact_pct"] = pixels ? 100.0 * double(exact) / double(pixels) : 0;
    state.counters["max_err_vs_ideal"] = maxErr;
    state.counters["mean_err_vs_ideal"] = sumErr / double(a->rgba.size() / 4 * 3);
    state.SetLabel(ps11::glRendererDescription());
}

}  // namespace

BENCHMARK_CAPTURE(BM_Glare, adaptive, std::string("adaptive"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);
BENCHMARK_CAPTURE(BM_Glare, glow, std::string("glow"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);
BENCHMARK_CAPTURE(BM_Glare, pyramid, std::string("pyramid"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);
BENCHMARK_CAPTURE(BM_Glare, quarter, std::string("quarter"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);
BENCHMARK_CAPTURE(BM_Glare, sprites, std::string("sprites"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);

BENCHMARK_MAIN();
