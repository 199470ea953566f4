// BM_Glare: every glare technique (published settings) on a 1920×1080 frame of its scene, run
// several ways in one process, frames interleaved under the same machine load: the emulator
// (software renderer, 2 worker threads unless PS11_THREADS says otherwise) as the 1.1-class card
// (fx8), as the 1.4-class card (radeon8500, fx12), under `float` and under `ideal`, and the GL renderer (Mesa llvmpipe
// through OSMesa, or EGL with PS11_GL=egl) in native mode — the peer (PERF.md) — and in exact mode. Before timing, one
// frame of each technique is compared pass by pass between the emulator and GL exact (glare/compare.h); the counters
// report that agreement, the fx8-vs-ideal error and the native-vs-fx8 error. A frame's time is its passes' own time
// (each pass ends when the renderer has finished it); for native mode also with the upload of the scene and the
// read-back of the result (`native_io_ms`). The benchmark's own time is the emulator's fx8 frame; every mode's median
// and the ratios to the peer are counters. These runners run every pass every frame (RunnerOptions::skip off; the
// *_tiles modes decide tiles but reuse no pass); two more
// hold the image with reuse on and time frames after the first (`*_still_*`), and four run the
// technique with skipping on over the moving `sparse` and `dense` scenes (`*_sparse_*`, `*_dense_*`; on the
// emulator also with it off, `*_noskip_*`, and the sparse frame's tile decisions on stderr). Per-pass medians of the
// timed modes go to stderr. bench/README.md "bench_glare".
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "emu/fullscreen.h"
#include "emu/thread_pool.h"
#include "glare/compare.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "ps11/hardware.h"
#include "runner/gl_backend.h"

namespace {

constexpr uint32_t kW = 1920, kH = 1080;

// The *_tiles modes: the emulator with its tiles decided (skipping on) but no pass reused from the
// last frame (RunnerOptions::reuse off), what a moving scene gets with the default options.
// EmuFx12: the radeon8500 class (fx12, MaxValue 8), the 1.4-class card.
enum Mode { EmuFx8, EmuIdeal, GlNative, GlExact, EmuFloat, EmuFx8Tiles, EmuFloatTiles, EmuFx12, kModes };
const char* const kModeNames[kModes] = {"emu_fx8",   "emu_ideal",     "gl_native",       "gl_exact",
                                        "emu_float", "emu_fx8_tiles", "emu_float_tiles", "emu_fx12"};

int threads() {
    const char* t = std::getenv("PS11_THREADS");
    return t ? std::atoi(t) : 2;
}

// Runners run every pass every frame (RunnerOptions::skip off) unless `skip`: the speed
// comparison is of whole frames; the still-frame counters measure what reuse saves.
std::unique_ptr<glare::Runner> makeRunner(Mode mode, std::string& err, bool skip = false, uint32_t w = kW,
                                          uint32_t h = kH) {
    glare::RunnerOptions ro;
    ro.width = w;
    ro.height = h;
    ro.skip = skip || mode == EmuFx8Tiles || mode == EmuFloatTiles;
    ro.reuse = skip;
    ro.device.software.threads = threads();
    if (mode == EmuIdeal) ro.device.precision = ps11::Precision::Ideal;
    if (mode == EmuFloat || mode == EmuFloatTiles) ro.device.precision = ps11::Precision::Float;
    if (mode == EmuFx12) ro.device.hardware = ps11::findHardware("radeon8500");
    if (mode == GlNative || mode == GlExact) {
        setenv("LP_NUM_THREADS", "2", 0);  // llvmpipe reads it when its screen is made
        const char* kind = std::getenv("PS11_GL");
        ro.device.renderer = ps11test::glRendererFactory(kind ? kind : "osmesa", err, mode == GlNative);
        if (!ro.device.renderer) return nullptr;
    }
    return std::make_unique<glare::Runner>(ro);
}

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

void BM_Glare(benchmark::State& state, const std::string& name) {
    const glare::Technique& t = *glare::findTechnique(name);
    const glare::Settings s = *glare::presetSettings(t, "published");
    std::string err;
    std::unique_ptr<glare::Runner> run[kModes];
    for (int m = 0; m < kModes; ++m)
        if (!(run[m] = makeRunner(Mode(m), err))) {
            state.SkipWithError(("no GL renderer: " + err).c_str());
            return;
        }
    std::unique_ptr<glare::Scene> scene = glare::makeScene(t.scene(), err);
    double ms = 0;
    std::optional<emu::RgbaImage> frame;
    if (!run[EmuFx8]->renderScene(*scene, 0, 8, ms, err) ||
        !(frame = run[EmuFx8]->readTexture(run[EmuFx8]->sceneTexture(), err))) {
        state.SkipWithError(err.c_str());
        return;
    }
    for (int m = 1; m < kModes; ++m)
        if (!run[m]->setImage(*frame, err)) {
            state.SkipWithError(err.c_str());
            return;
        }
    // Agreement of GL exact, pass-isolated, then frame 0 on the others; errors of the outputs.
    std::vector<glare::PassAgreement> agreement;
    glare::FrameResult r;
    if (!glare::compareFrame(*run[EmuFx8], *run[GlExact], t, s, 0, 2, agreement, r, err) ||
        !run[EmuIdeal]->runFrame(t, s, 0, 2, r, err) || !run[EmuFloat]->runFrame(t, s, 0, 2, r, err) ||
        !run[EmuFx12]->runFrame(t, s, 0, 2, r, err) || !run[GlNative]->runFrame(t, s, 0, 2, r, err)) {
        state.SkipWithError(err.c_str());
        return;
    }
    uint64_t pixels = 0, exact = 0;
    for (const glare::PassAgreement& a : agreement) pixels += a.pixels, exact += a.exact;
    std::optional<emu::RgbaImage> fx8 = run[EmuFx8]->readOutput(err), ideal = run[EmuIdeal]->readOutput(err),
                                  native = run[GlNative]->readOutput(err);
    if (!fx8 || !ideal || !native) {
        state.SkipWithError(err.c_str());
        return;
    }
    const glare::ImageError fx8VsIdeal = glare::imageError(*fx8, *ideal), nativeVsFx8 = glare::imageError(*native, *fx8);

    // Native mode's I/O at the device's level: the scene's pixels written to its surface (a lock
    // of a staging surface made once, a copy, StretchRect) and the result read back where the
    // device keeps it (Device::readSurface); the harness's own image conversions are outside it.
    // Nothing is allocated per frame: on this machine's host, 8 MB allocated and given back made
    // the frames of the runners after it slower (bench/README.md "Memory given back").
    const emu::SurfacePixels scenePixels = emu::surfacePixels(
        [&] {
            emu::FloatImage f;
            f.width = frame->width, f.height = frame->height;
            for (uint8_t b : frame->rgba) f.rgba.push_back(float(b) / 255.0f);
            return f;
        }(),
        run[GlNative]->intermediateFormat());
    emu::Handle nativeScene{}, nativeOut{}, staging{};
    emu::Device& nativeDevice = run[GlNative]->device();
    if (nativeDevice.GetSurfaceLevel(run[GlNative]->sceneTexture(), 0, &nativeScene) != emu::D3D_OK ||
        nativeDevice.GetSurfaceLevel(run[GlNative]->outputTexture(), 0, &nativeOut) != emu::D3D_OK ||
        nativeDevice.CreateOffscreenPlainSurface(kW, kH, scenePixels.format, emu::D3DPOOL_DEFAULT, &staging) != emu::D3D_OK) {
        state.SkipWithError(nativeDevice.lastError().message.c_str());
        return;
    }
    // One upload: the pixels into the staging surface, then StretchRect to the scene.
    auto upload = [&]() {
        emu::D3DLOCKED_RECT lr{};
        if (nativeDevice.LockRect(staging, &lr, nullptr, 0) != emu::D3D_OK) return false;
        const size_t row = size_t(kW) * scenePixels.bytesPerPixel;
        for (uint32_t y = 0; y < kH; ++y)
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch), &scenePixels.bytes[y * row], row);
        return nativeDevice.UnlockRect(staging) == emu::D3D_OK &&
               nativeDevice.StretchRect(staging, nullptr, nativeScene, nullptr, emu::D3DTEXF_POINT) == emu::D3D_OK;
    };
    uint64_t readSum = 0;  // a byte of every read-back row, so the read is used
    std::vector<double> frameMs[kModes], nativeIoMs;
    std::map<std::string, std::vector<double>> passMs[kModes];
    std::vector<std::string> passOrder;
    // A moving scene: two more runners (emulator fx8, GL native) draw the scene's next frame on
    // their own renderer before each timed frame, so the technique's first reads of a freshly
    // drawn target are in the time, as in an application.
    // A third decides tiles (the scene's tile facts are then taken anew every frame).
    std::unique_ptr<glare::Runner> moving[3];
    std::unique_ptr<glare::Scene> movingScene[3];  // a Scene serves one device
    const Mode movingMode[3] = {EmuFx8, GlNative, EmuFx8Tiles};
    for (int k = 0; k < 3; ++k)
        if (!(moving[k] = makeRunner(movingMode[k], err)) || !(movingScene[k] = glare::makeScene(t.scene(), err))) {
            state.SkipWithError(err.c_str());
            return;
        }
    std::vector<double> movingMs[3];
    // A still input with reuse on (the default of ps11 glare): two more runners (emulator fx8, GL
    // native) hold the same image; their first frame runs before timing, so every timed frame is
    // one after the first, against the same renderer's whole frame (skip off) above.
    std::unique_ptr<glare::Runner> still[2];
    for (int k = 0; k < 2; ++k) {
        glare::FrameResult fr;
        if (!(still[k] = makeRunner(movingMode[k], err, true)) || !still[k]->setImage(*frame, err) ||
            !still[k]->runFrame(t, s, 0, 2, fr, err)) {
            state.SkipWithError(err.c_str());
            return;
        }
    }
    std::vector<double> stillMs[2];
    // Skipping's measuring scenes (docs/glare/scenes.md): `sparse` and `dense`, moving, with
    // reuse on, on the emulator (fx8) and GL native; each draws the scene's next frame before
    // the timed frame (not timed). The sprites technique draws a sprite per bright pixel (about
    // 20 000 on sparse at 1080p, 2 million on dense: over a minute a frame), so it runs them at
    // 480x270.
    const bool quarterSize = name == "sprites";
    const uint32_t panelW = quarterSize ? kW / 4 : kW, panelH = quarterSize ? kH / 4 : kH;
    state.counters["panel_width"] = panelW;
    // [sparse, dense][emu fx8, GL native, emu fx8 with --no-skip (no reuse, every tile shaded)]
    std::unique_ptr<glare::Runner> panel[2][3];
    std::unique_ptr<glare::Scene> panelScene[2][3];
    for (int d = 0; d < 2; ++d)
        for (int k = 0; k < 3; ++k)
            if (!(panel[d][k] = makeRunner(k == 2 ? EmuFx8 : movingMode[k], err, k != 2, panelW, panelH)) ||
                !(panelScene[d][k] = glare::makeScene(d ? "dense" : "sparse", err))) {
                state.SkipWithError(err.c_str());
                return;
            }
    std::vector<double> panelMs[2][3];
    uint64_t sparseBytes = 0;
    // The host's memory speed in the same run: one 1080p RGBA8 target copied into another by the
    // emulator's workers (emu::parallelCopy), timed once per iteration between the frames (the
    // buffers made once). Its bytes are counted as PassStats::bytes counts a pass's (read and
    // written), so the sparse frame's floor in bytes over this speed is that floor in time on
    // this host, today. Runner::copySpeed's warm and cold copies, after the frames, bound it.
    const size_t probeBytes = size_t(kW) * kH * 4;
    std::vector<uint8_t> probeFrom(probeBytes, 1), probeTo(probeBytes, 0);
    const std::shared_ptr<emu::ThreadPool> probePool = emu::ThreadPool::shared(threads());
    std::vector<double> probeMs;
    auto probe = [&] {
        const auto t0 = std::chrono::steady_clock::now();
        emu::parallelCopy(*probePool, probeTo.data(), probeFrom.data(), probeBytes);
        probeMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    };
    probe();  // (the pages touched once before timing)
    probeMs.clear();
    glare::FrameResult sparseFrame;  // the last sparse frame on the emulator, for its tile counts
    int f = 1;
    for (auto _ : state) {
        probe();
        for (int d = 0; d < 2; ++d)
            for (int k = 0; k < 3; ++k) {
                double sceneMs = 0;
                glare::FrameResult fr;
                if (!panel[d][k]->renderScene(*panelScene[d][k], f % 60, 60, sceneMs, err) ||
                    !panel[d][k]->runFrame(t, s, f, f + 1, fr, err)) {
                    state.SkipWithError(err.c_str());
                    return;
                }
                panelMs[d][k].push_back(fr.milliseconds);
                if (d == 0 && k == 0) {
                    sparseBytes = 0;
                    for (const glare::PassStats& p : fr.passes) sparseBytes += p.bytes;
                    sparseFrame = fr;
                }
            }
        for (int k = 0; k < 2; ++k) {
            glare::FrameResult fr;
            if (!still[k]->runFrame(t, s, f, f + 1, fr, err)) {
                state.SkipWithError(err.c_str());
                return;
            }
            stillMs[k].push_back(fr.milliseconds);
        }
        for (int k = 0; k < 3; ++k) {
            double sceneMs = 0;
            glare::FrameResult fr;
            if (!moving[k]->renderScene(*movingScene[k], f % 8, 8, sceneMs, err) || !moving[k]->runFrame(t, s, f, f + 1, fr, err)) {
                state.SkipWithError(err.c_str());
                return;
            }
            movingMs[k].push_back(fr.milliseconds);
        }
        for (int m = 0; m < kModes; ++m) {
            // Native mode with its I/O: the scene handed over and the result read back.
            const auto t0 = std::chrono::steady_clock::now();
            if (m == GlNative) {
                if (!upload()) {
                    err = nativeDevice.lastError().message;
                    break;
                }
                run[m]->device().finish();
            }
            const double upMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            glare::FrameResult fr;
            if (!run[m]->runFrame(t, s, f, f + 1, fr, err)) {
                state.SkipWithError(err.c_str());
                return;
            }
            if (m == GlNative) {
                const auto t1 = std::chrono::steady_clock::now();
                if (nativeDevice.readSurface(nativeOut, [&](const emu::D3DLOCKED_RECT& lr) {
                        for (uint32_t y = 0; y < kH; ++y)
                            readSum += static_cast<const uint8_t*>(lr.pBits)[size_t(y) * size_t(lr.Pitch)];
                    }) != emu::D3D_OK) {
                    err = nativeDevice.lastError().message;
                    break;
                }
                nativeIoMs.push_back(upMs + fr.milliseconds +
                                     std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count());
            }
            frameMs[m].push_back(fr.milliseconds);
            for (const glare::PassStats& p : fr.passes) {
                if (m == 0 && f == 1) passOrder.push_back(p.pass);
                passMs[m][p.pass].push_back(p.milliseconds);
            }
            if (m == EmuFx8) state.SetIterationTime(fr.milliseconds / 1000);
        }
        if (!err.empty()) {
            state.SkipWithError(err.c_str());
            return;
        }
        ++f;
    }
    double med[kModes];
    for (int m = 0; m < kModes; ++m) {
        med[m] = median(frameMs[m]);
        state.counters[std::string(kModeNames[m]) + "_ms"] = med[m];
    }
    // Ratios to the peer (> 1: faster than GL native).
    state.counters["fx8_speedup_vs_native"] = med[GlNative] / med[EmuFx8];
    state.counters["ideal_speedup_vs_native"] = med[GlNative] / med[EmuIdeal];
    state.counters["float_speedup_vs_native"] = med[GlNative] / med[EmuFloat];
    state.counters["fx12_speedup_vs_native"] = med[GlNative] / med[EmuFx12];
    state.counters["fx8_tiles_speedup_vs_native"] = med[GlNative] / med[EmuFx8Tiles];
    state.counters["float_tiles_speedup_vs_native"] = med[GlNative] / med[EmuFloatTiles];
    state.counters["exact_over_native"] = med[GlExact] / med[GlNative];
    state.counters["emu_fx8_moving_ms"] = median(movingMs[0]);
    state.counters["gl_native_moving_ms"] = median(movingMs[1]);
    state.counters["fx8_moving_speedup_vs_native"] = median(movingMs[1]) / median(movingMs[0]);
    state.counters["emu_fx8_tiles_moving_ms"] = median(movingMs[2]);
    state.counters["fx8_tiles_moving_speedup_vs_native"] = median(movingMs[1]) / median(movingMs[2]);
    state.counters["native_io_ms"] = median(nativeIoMs);
    benchmark::DoNotOptimize(readSum);
    state.counters["emu_fx8_sparse_ms"] = median(panelMs[0][0]);
    state.counters["emu_fx8_dense_ms"] = median(panelMs[1][0]);
    state.counters["gl_native_sparse_ms"] = median(panelMs[0][1]);
    state.counters["gl_native_dense_ms"] = median(panelMs[1][1]);
    state.counters["fx8_sparse_pct"] = 100.0 * median(panelMs[0][0]) / median(panelMs[1][0]);
    state.counters["native_sparse_pct"] = 100.0 * median(panelMs[0][1]) / median(panelMs[1][1]);
    // What skipping saves on the moving scenes, and the sparse frame's floor: the bytes its passes
    // must move at least (each texture read and written once), over its time.
    state.counters["emu_fx8_sparse_noskip_ms"] = median(panelMs[0][2]);
    state.counters["emu_fx8_dense_noskip_ms"] = median(panelMs[1][2]);
    state.counters["fx8_sparse_vs_noskip_pct"] = 100.0 * median(panelMs[0][0]) / median(panelMs[0][2]);
    state.counters["fx8_dense_vs_noskip_pct"] = 100.0 * median(panelMs[1][0]) / median(panelMs[1][2]);
    state.counters["fx8_sparse_floor_mb"] = double(sparseBytes) / 1e6;
    state.counters["fx8_sparse_gbps"] = double(sparseBytes) / 1e6 / median(panelMs[0][0]);
    const double copyGbps = 2.0 * double(probeBytes) / 1e6 / median(probeMs);
    state.counters["copy_gbps"] = copyGbps;
    const glare::Runner::CopySpeed bounds = run[EmuFx8]->copySpeed();
    state.counters["copy_warm_gbps"] = bounds.warm;
    state.counters["copy_cold_gbps"] = bounds.cold;
    state.counters["fx8_sparse_floor_ms"] = double(sparseBytes) / 1e6 / copyGbps;
    state.counters["fx8_sparse_over_floor"] = median(panelMs[0][0]) / (double(sparseBytes) / 1e6 / copyGbps);
    uint64_t tiles[4] = {};
    for (const glare::PassStats& p : sparseFrame.passes) {
        tiles[0] += p.tilesShaded, tiles[1] += p.tilesFilled, tiles[2] += p.tilesCopied, tiles[3] += p.tilesSkipped;
        if (p.tilesShaded + p.tilesFilled + p.tilesCopied + p.tilesSkipped)
            std::fprintf(stderr, "%s sparse %s: tiles shaded %llu filled %llu copied %llu skipped %llu\n", name.c_str(),
                         p.pass.c_str(), (unsigned long long)p.tilesShaded, (unsigned long long)p.tilesFilled,
                         (unsigned long long)p.tilesCopied, (unsigned long long)p.tilesSkipped);
    }
    state.counters["fx8_sparse_tiles_shaded"] = double(tiles[0]);
    state.counters["fx8_sparse_tiles_decided"] = double(tiles[1] + tiles[2] + tiles[3]);
    state.counters["emu_fx8_still_ms"] = median(stillMs[0]);
    state.counters["gl_native_still_ms"] = median(stillMs[1]);
    state.counters["fx8_still_pct"] = 100.0 * median(stillMs[0]) / med[EmuFx8];
    state.counters["native_still_pct"] = 100.0 * median(stillMs[1]) / med[GlNative];
    state.counters["exact_pct"] = pixels ? 100.0 * double(exact) / double(pixels) : 0;
    state.counters["fx8_vs_ideal_max"] = fx8VsIdeal.max;
    state.counters["fx8_vs_ideal_mean"] = fx8VsIdeal.mean;
    state.counters["native_vs_fx8_max"] = nativeVsFx8.max;
    state.counters["native_vs_fx8_mean"] = nativeVsFx8.mean;
    state.SetLabel(ps11test::glRendererDescription());
    std::fprintf(stderr, "%s, per pass (median ms): %-22s", name.c_str(), "pass");
    for (int m = 0; m < kModes; ++m) std::fprintf(stderr, " %15s", kModeNames[m]);
    std::fprintf(stderr, "\n");
    for (const std::string& p : passOrder) {
        std::fprintf(stderr, "%s, per pass (median ms): %-22s", name.c_str(), p.c_str());
        for (int m = 0; m < kModes; ++m) std::fprintf(stderr, " %15.3f", median(passMs[m][p]));
        std::fprintf(stderr, "\n");
    }
}

}  // namespace

BENCHMARK_CAPTURE(BM_Glare, adaptive, std::string("adaptive"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);
BENCHMARK_CAPTURE(BM_Glare, glow, std::string("glow"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);
BENCHMARK_CAPTURE(BM_Glare, pyramid, std::string("pyramid"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);
BENCHMARK_CAPTURE(BM_Glare, quarter, std::string("quarter"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);
BENCHMARK_CAPTURE(BM_Glare, sprites, std::string("sprites"))->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(7);

BENCHMARK_MAIN();
