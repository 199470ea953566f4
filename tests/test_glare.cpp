// The glare techniques (glare/): the shaders, every technique on both renderers, and GLARE.md's
// behaviours with thresholds derived from its formulas (adaptation, weights, pyramid, glow), the
// runner's read-back and the fits-ps_1_1 report. The pass graph is tested in
// test_glare_graph.cpp, the sprites in test_glare_sprites.cpp, reuse and tile skipping in
// test_glare_reuse.cpp; the helpers they share are in glare_test_util.h.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "emu/fullscreen.h"
#include "glare/compare.h"
#include "glare/glow.h"
#include "glare/passes.h"
#include "glare/report.h"
#include "glare/runner.h"
#include "glare/scene.h"
#include "glare/shader_library.h"
#include "glare/stress.h"
#include "simd_levels.h"
#include "glare_test_util.h"
#include "ps11/assembler.h"
#include "ps11/validator.h"
#include "runner/gl_backend.h"

using namespace glare;

using namespace glaretest;

namespace {

// The value of a 1x1 (or the first texel of a) texture, as stored: floats read exactly.
std::array<double, 4> texel(Runner& r, emu::Handle texture) {
    emu::Handle s{};
    REQUIRE(r.device().GetSurfaceLevel(texture, 0, &s) == D3D_OK);
    std::string err;
    std::optional<emu::SurfacePixels> px = emu::readSurface(r.device(), s, err);
    REQUIRE(px);
    std::array<double, 4> v{};
    if (px->format == D3DFMT_A8R8G8B8) {
        v = {px->bytes[2] / 255.0, px->bytes[1] / 255.0, px->bytes[0] / 255.0, px->bytes[3] / 255.0};
    } else {
        float f[4];
        std::memcpy(f, px->bytes.data(), 16);
        v = {f[0], f[1], f[2], f[3]};
    }
    return v;
}

}  // namespace

TEST_CASE("every glare shader assembles and validates as ps_1_1", "[glare]") {
    REQUIRE(embeddedShaders().size() >= 10);
    for (const EmbeddedShader& s : embeddedShaders()) {
        INFO(s.name);
        ps11::Diagnostics diags;
        std::optional<ps11::Program> p = ps11::parseAssembly(s.text, std::string(s.name), {}, diags);
        REQUIRE(p);
        ps11::ShaderStats stats;
        CHECK(ps11::validate(*p, diags, &stats));
        CHECK(stats.version.minor == 1);
        CHECK(stats.texSlots <= stats.texLimit);
        CHECK(stats.arithSlots <= stats.arithLimit);
    }
}

TEST_CASE("the embedded shaders are the files in glare/shaders", "[glare]") {
    for (const EmbeddedShader& s : embeddedShaders()) {
        std::ifstream f(std::string(PS11_SOURCE_DIR) + "/glare/shaders/" + std::string(s.name), std::ios::binary);
        REQUIRE(f);
        std::stringstream text;
        text << f.rdbuf();
        CHECK(text.str() == s.text);
    }
}

TEST_CASE("every technique and preset runs and matches the GL renderer pass by pass", "[glare][gl]") {
    std::string error;
    const ps11test::RendererFactory gl = ps11test::glRendererFactory("", error);
    REQUIRE(gl);
    for (const Technique* t : techniques())
        for (std::string_view presetName : kPresetNames) {
            INFO(std::string(t->name()) + " " + std::string(presetName));
            Runner emuRun(options(96, 64));
            RunnerOptions glOptions = options(96, 64);
            glOptions.device.renderer = gl;
            Runner glRun(glOptions);
            std::string sceneError;
            std::unique_ptr<Scene> scene = makeScene(t->name() == "sprites" ? "lights" : "box", sceneError);
            REQUIRE(scene);
            double ms = 0;
            REQUIRE(emuRun.renderScene(*scene, 3, 8, ms, error));
            std::optional<emu::RgbaImage> frame = emuRun.readTexture(emuRun.sceneTexture(), error);
            REQUIRE(frame);
            REQUIRE(glRun.setImage(*frame, error));
            std::vector<PassAgreement> agreement;
            FrameResult result;
            const Settings s = *presetSettings(*t, presetName);
            for (int f = 0; f < 2; ++f) REQUIRE(compareFrame(emuRun, glRun, *t, s, f, 2, agreement, result, error));
            REQUIRE(!agreement.empty());
            for (const PassAgreement& a : agreement) {
                INFO(a.pass << ": " << a.overOne << " of " << a.pixels << " pixels past 1 level, max " << a.maxDiff);
                CHECK(a.overOne == 0);
            }
        }
}

TEST_CASE("adaptive: the glare amount follows A_n = a·L + (1 − a)·A_(n−1), and stops short in 8 bits", "[glare]") {
    // A uniform grey 0.5 squared by mul_x4: 4·avg² = 1 per channel, luminance 1.0 (clamped), so
    // L = 1 in both profiles (the published square, avg·min(4·avg, 1), gives 0.5 on the card and
    // 1 under ideal). From black, ideal: A_n = 1 − (1 − a)^n. fx8 with round-to-nearest stops
    // where the step a·(L − A) falls below half a level: about 0.5/a = 20 levels short (GLARE.md §7).
    const Technique& t = *findTechnique("adaptive");
    Settings s = preset("adaptive");
    s["start"] = 1;   // black
    s["square"] = 1;  // mul_x4
    const double a = s.at("smoothing");
    for (auto p : {ps11::Precision::Ideal, ps11::Precision::Fx8}) {
        Runner run(options(16, 16, p));
        std::string err;
        REQUIRE(run.setImage(uniform(16, 16, 0.5f, 0.5f, 0.5f), err));
        std::vector<double> values;
        for (int f = 0; f < 400; ++f) {
            FrameResult r;
            REQUIRE(run.runFrame(t, s, f, 400, r, err));
            values.push_back(texel(run, run.persistent("adapted glare amount", {1, 1, run.intermediateFormat()}, 0, err))[0]);
        }
        if (p == ps11::Precision::Ideal) {
            for (int n : {1, 10, 50, 100, 200}) {
                INFO("frame " << n);
                CHECK(values[size_t(n - 1)] == Approx(1 - std::pow(1 - a, n)).margin(1e-4));
            }
        } else {
            // The 8-bit recurrence, exactly (glare/stress.h, the prediction `ps11 stress` prints): the
            // smoothing constant sits on the grid, the blend rounds once to a level, ties to even.
            const std::vector<int> predicted = predictSmoothingLevels(a, 255, 0, 400);
            for (int f = 0; f < 400; ++f) {
                INFO("frame " << f);
                REQUIRE(values[size_t(f)] * 255 == Approx(predicted[size_t(f)]).margin(1e-6));
            }
            // Stuck below 1.0 by the dead band (the stress suite's smoothing_dead_band measures its size
            // from both sides), and no longer moving.
            CHECK(values.back() < 1.0);
            CHECK(values[399] == values[300]);
        }
    }
}

TEST_CASE("adaptive: the ps_1_1 bright pass computes b·min(4b, 1), ideal computes 4b²", "[glare]") {
    const Technique& t = *findTechnique("adaptive");
    for (float c : {0.5f, 0.6f, 0.8f}) {
        const double b = c - 0.4, intended = std::min(4 * b * b, 1.0), hardware = b * std::min(4 * b, 1.0);
        for (auto p : {ps11::Precision::Ideal, ps11::Precision::Fx8}) {
            Runner run(options(16, 16, p));
            std::string err;
            REQUIRE(run.setImage(uniform(16, 16, c, c, c), err));
            Settings s = preset("adaptive");
            s["glare_amount"] = 1;
            s["blur_passes"] = 0;
            s["start"] = 1;      // black, and
            s["smoothing"] = 0;  // kept black: A = 0, 1 − A = 1
            PassGraph* graph = nullptr;
            double value = -1;
            FrameResult r;
            // Read the bright pass's target right after it ran (A is that frame's amount).
            REQUIRE(run.runFrame(
                t, s, 0, 1, r, err,
                [&](uint32_t pass, bool after, std::string&) {
                    if (after && graph->passes()[pass].info.name == "bright_pass")
                        value = texel(run, graph->texture(graph->passes()[pass].writes[0]).device)[0];
                    return true;
                },
                [&](PassGraph& g) { graph = &g; }));
            INFO("c = " << c << " profile " << int(p));
            if (p == ps11::Precision::Ideal)
                CHECK(value == Approx(intended).margin(0.02));
            else
                CHECK(value == Approx(hardware).margin(0.02));
        }
    }
}

TEST_CASE("error-diffused weights keep the kernel's sum on the grid", "[glare]") {
    // GLARE.md §7: rounding each 8-bit weight of a normalised kernel gives Σw ≈ 1.0039; carrying the
    // remainder keeps the quantised sum equal to the quantised real sum.
    const std::vector<std::vector<double>> kernels = {
        {5.0 / 16, 6.0 / 16, 5.0 / 16}, {0.25, 0.25, 0.25, 0.25}, {1.0 / 3, 1.0 / 3, 1.0 / 3}};
    for (const auto& k : kernels) {
        const double sum = std::accumulate(k.begin(), k.end(), 0.0);
        const std::vector<double> q = quantiseWeights(k, ps11::Precision::Fx8);
        CHECK(std::accumulate(q.begin(), q.end(), 0.0) * 255 == Approx(std::nearbyint(sum * 255)).margin(1e-9));
        for (size_t i = 0; i < q.size(); ++i) {
            CHECK(std::fabs(q[i] * 255 - std::nearbyint(q[i] * 255)) < 1e-9);  // on the grid
            CHECK(std::fabs(q[i] - k[i]) <= 1.0 / 255);                       // within a level of the real weight
        }
    }
    // The pyramid's 5/16, 6/16, 5/16 rounded one by one sum to 256/255: the reason diffusion exists.
    double naive = 0;
    for (double w : kernels[0]) naive += std::nearbyint(w * 255);
    CHECK(naive == 256);
    // Float profiles keep the weights as they are.
    CHECK(quantiseWeights(kernels[0], ps11::Precision::Ideal) == kernels[0]);
}

TEST_CASE("pyramid: DC gain 4 when summed plainly, 1 when energy-normalised", "[glare]") {
    // A uniform 0.1 with threshold 0: the bright pass keeps 0.1; every level stays 0.1; the sum of
    // four levels is 0.4 plainly and 0.1 normalised; the composite adds it to the scene.
    const Technique& t = *findTechnique("pyramid");
    for (int sum : {0, 1})
        for (auto p : {ps11::Precision::Ideal, ps11::Precision::Fx8}) {
            Runner run(options(64, 64, p));
            std::string err;
            REQUIRE(run.setImage(uniform(64, 64, 0.1f, 0.1f, 0.1f), err));
            Settings s = preset("pyramid");
            s["threshold"] = 0;
            s["sum"] = sum;
            s["size"] = 64;
            FrameResult r;
            REQUIRE(run.runFrame(t, s, 0, 1, r, err));
            std::optional<emu::RgbaImage> out = run.readOutput(err);
            REQUIRE(out);
            const double expected = 0.1 + (sum == 0 ? 0.4 : 0.1);
            INFO("sum " << sum << " profile " << ps11::precisionName(p));
            // The output is 8-bit: the scene copy (25.5 levels) and the sum each round by up to half a
            // level; fx8 also rounds the input and every pass (four levels weighted and summed).
            CHECK(int(out->rgba[size_t(32 * 64 + 32) * 4]) == Approx(expected * 255).margin(p == ps11::Precision::Ideal ? 1 : 4));
        }
}

TEST_CASE("glow: feedback decays by k per frame, and 8-bit rounding leaves a residue that never fades", "[glare]") {
    // A uniform source (alpha 1), then black. Uniform images make the blur an identity (the
    // kernel sums to 1), so the glow is y ← s + k·y: y → s/(1 − k), then y ← k·y once s = 0.
    // With rounding, y ← Q(k·y) stops at a residue of about 0.5/(1 − k) levels (GLARE.md §7).
    const Technique& t = *findTechnique("glow");
    Settings s = preset("glow");
    s["afterimage"] = 2;  // feedback
    s["decay"] = 0.8;
    s["radius"] = 2;
    for (auto p : {ps11::Precision::Ideal, ps11::Precision::Fx8}) {
        Runner run(options(32, 32, p));
        std::string err;
        std::vector<double> glow;
        for (int f = 0; f < 60; ++f) {
            REQUIRE(run.setImage(f < 20 ? uniform(32, 32, 0.1f, 0.1f, 0.1f) : uniform(32, 32, 0, 0, 0), err));
            FrameResult r;
            REQUIRE(run.runFrame(t, s, f, 60, r, err));
            glow.push_back(texel(run, run.persistent("previous glow", {8, 8, run.intermediateFormat()}, 0, err))[0]);
        }
        INFO("profile " << int(p));
        // Converged near s/(1 − k) = 0.5 after 20 frames (0.8^20 ≈ 1 %).
        CHECK(glow[19] == Approx(0.5).margin(p == ps11::Precision::Ideal ? 0.01 : 0.03));
        if (p == ps11::Precision::Ideal) {
            for (int f = 21; f < 30; ++f) CHECK(glow[size_t(f)] == Approx(0.8 * glow[size_t(f - 1)]).epsilon(1e-3));
            CHECK(glow[59] * 255 < 0.5);  // fades below half a level
        } else {
            // Once the source is black: y ← B_v(B_h(round(k8·y/255))) (glare/stress.h, predicted frame
            // by frame from frame 19's value): it must match exactly, and stop at a residue that never fades.
            const std::vector<int> predicted = predictFeedbackLevels(s, int(std::nearbyint(glow[19] * 255)), 40);
            for (int f = 20; f < 60; ++f) {
                INFO("frame " << f);
                REQUIRE(glow[size_t(f)] * 255 == Approx(predicted[size_t(f - 20)]).margin(1e-6));
            }
            const int y = predicted.back();
            CHECK(y >= 1);
            CHECK(glow[59] == glow[50]);
        }
    }
}

TEST_CASE("frameBytes is frameByte for every float", "[glare]") {
    // Specials, the ends of [0, 1], every value near a rounding boundary, random bits; lengths
    // around the vector blocks (16 and 32 values); at every SIMD level.
    std::vector<float> v = {NAN, -NAN, INFINITY, -INFINITY, 0.0f, -0.0f, 1.0f, 1.0001f, -1e-30f, 1e30f};
    for (int k = 0; k < 256; ++k) {
        const float b = (float(k) + 0.5f) / 255.0f;
        v.insert(v.end(), {b, std::nextafter(b, 0.0f), std::nextafter(b, 1.0f)});
    }
    std::mt19937 rng(5);
    for (int i = 0; i < 3000; ++i) {
        uint32_t bits = rng();
        float f;
        std::memcpy(&f, &bits, 4);
        v.push_back(i % 2 ? f : float(rng() % 70000) / 65536.0f);
    }
    testutil::forEachSimdLevel([&](ps11::SimdLevel) {
        for (size_t n : {size_t(0), size_t(5), size_t(16), size_t(17), size_t(31), size_t(32), size_t(33), size_t(63),
                         size_t(64), size_t(65), v.size()}) {
            std::vector<uint8_t> got(n + 1, 0xAB);
            glare::frameBytes(v.data(), n, got.data());
            size_t bad = 0;
            for (size_t i = 0; i < n; ++i) bad += got[i] != glare::frameByte(v[i]);
            INFO("length " << n);
            CHECK(bad == 0);
            CHECK(got[n] == 0xAB);
        }
    });
}

TEST_CASE("runner: readTexture gives each texel as r g b a, into an image it reuses", "[glare]") {
    // An odd size (rows of any length), random bytes in fx8's A8R8G8B8 and random floats (below
    // 0, above 1, NaN) in ideal's A32B32G32R32F: the bytes read are the texels' own, the floats'
    // frameByte; reading into an image that held something else gives the same.
    std::mt19937 rng(11);
    const uint32_t w = 37, h = 5;
    emu::RgbaImage bytes{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
    for (uint8_t& b : bytes.rgba) b = uint8_t(rng());
    emu::FloatImage floats{w, h, std::vector<float>(size_t(w) * h * 4)};
    for (size_t i = 0; i < floats.rgba.size(); ++i)
        floats.rgba[i] = i == 7 ? NAN : float(int(rng() % 4000) - 1000) / 2000.0f;
    std::vector<uint8_t> floatBytes;
    for (float f : floats.rgba) floatBytes.push_back(glare::frameByte(f));
    for (const bool ideal : {false, true}) {
        INFO((ideal ? "ideal" : "fx8"));
        glare::RunnerOptions o;
        o.width = w;
        o.height = h;
        if (ideal) o.device.precision = ps11::Precision::Ideal;
        glare::Runner run(o);
        std::string err;
        REQUIRE((ideal ? run.setImage(floats, err) : run.setImage(bytes, err)));
        const std::vector<uint8_t>& want = ideal ? floatBytes : bytes.rgba;
        const std::optional<emu::RgbaImage> once = run.readTexture(run.sceneTexture(), err);
        REQUIRE(once);
        CHECK(once->width == w);
        CHECK(once->height == h);
        CHECK(once->rgba == want);
        emu::RgbaImage reused{3, 2, std::vector<uint8_t>(size_t(64) * 64 * 4, 0x5A)};
        REQUIRE(run.readTexture(run.sceneTexture(), reused, err));
        CHECK(reused.width == w);
        CHECK(reused.height == h);
        CHECK(reused.rgba == want);
        CHECK_FALSE(run.readTexture(emu::Handle{}, reused, err));
        CHECK_FALSE(err.empty());
    }
}

TEST_CASE("docs/fits-ps11.md is what ps11 glare --report --markdown prints", "[glare][docs]") {
    std::ifstream f(std::string(PS11_SOURCE_DIR) + "/docs/fits-ps11.md", std::ios::binary);
    REQUIRE(f);
    std::stringstream text;
    text << f.rdbuf();
    const FitsReport r = fitsReport();
    CHECK(text.str() == fitsReportMarkdown(r));
    // Every shader pass fits; the only step past 1.1 is Ando's sensors.
    for (const PassFit& p : r.passes) {
        INFO(p.technique << " " << p.preset << " " << p.pass);
        if (p.pass == "sensors")
            CHECK_FALSE(p.fits);
        else
            CHECK(p.fits);
    }
}

TEST_CASE("runner: under ideal an 8-bit scene gives the frames the same image gives as a float scene", "[glare]") {
    // An 8-bit input stays in an A8R8G8B8 scene under ideal (Runner::setImage): its texels read as
    // the n/255 the float scene would hold, through every pass (draws, StretchRect reductions,
    // the sprites' sensors, copies to the output). Each technique, three frames of its moving
    // scene, both ways: the outputs byte for byte.
    for (const Technique* t : techniques()) {
        INFO(t->name());
        Runner eight(options(160, 96, ps11::Precision::Ideal)), floats(options(160, 96, ps11::Precision::Ideal));
        std::string error;
        std::unique_ptr<Scene> scene = makeScene(t->scene(), error);
        REQUIRE(scene);
        const Settings s = *presetSettings(*t, "published");
        for (int f = 0; f < 3; ++f) {
            double ms = 0;
            REQUIRE(eight.renderScene(*scene, f, 8, ms, error));
            CHECK(eight.sceneFormat() == D3DFMT_A8R8G8B8);
            std::optional<emu::RgbaImage> frame = eight.readTexture(eight.sceneTexture(), error);
            REQUIRE(frame);
            emu::FloatImage image;
            image.width = frame->width, image.height = frame->height;
            for (uint8_t b : frame->rgba) image.rgba.push_back(float(b) / 255.0f);
            REQUIRE(floats.setImage(image, error));
            CHECK(floats.sceneFormat() == D3DFMT_A32B32G32R32F);
            FrameResult a, b;
            REQUIRE(eight.runFrame(*t, s, f, 8, a, error));
            REQUIRE(floats.runFrame(*t, s, f, 8, b, error));
            std::optional<emu::RgbaImage> outA = eight.readOutput(error), outB = floats.readOutput(error);
            REQUIRE(outA);
            REQUIRE(outB);
            CHECK(outA->rgba == outB->rgba);
        }
    }
}
