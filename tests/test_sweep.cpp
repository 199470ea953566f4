// The run-time-against-error sweep (glare/sweep.h) and the intended math (glare/intended.h): the
// rows a sweep makes, the ideal row's zero error, the Pareto front's definition, and the intended
// results on inputs whose answer is known.
#include <catch2/catch.hpp>

#include <cmath>

#include "glare/intended.h"
#include "glare/sweep.h"
#include "glare/technique.h"

namespace {

// Each row on the front is beaten by no row of its group; each row off it is beaten by one on it.
void checkFront(const std::vector<glare::SweepRow>& rows) {
    for (const glare::SweepRow& b : rows) {
        bool dominated = false, dominatedByFront = false;
        for (const glare::SweepRow& a : rows)
            if (&a != &b && glare::dominates(a, b)) {
                dominated = true;
                dominatedByFront = dominatedByFront || a.pareto;
            }
        CHECK(b.pareto == !dominated);
        if (!b.pareto) CHECK(dominatedByFront);
    }
}

glare::SweepRow row(double ms, double mean, int max) {
    glare::SweepRow r;
    r.technique = "glow", r.scene = "neon", r.width = 64, r.height = 36;
    r.msMedian = ms;
    r.error.mean = mean;
    r.error.max = max;
    return r;
}

emu::FloatImage uniform(uint32_t w, uint32_t h, float v, float a = 1.0f) {
    emu::FloatImage img;
    img.width = w, img.height = h;
    img.rgba.assign(size_t(w) * h * 4, v);
    for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = a;
    return img;
}

}  // namespace

TEST_CASE("sweep: a tiny sweep makes one row per combination, ideal's row is exact, the front is undominated",
          "[sweep]") {
    glare::SweepSpec spec;
    spec.techniques = {glare::findTechnique("adaptive")};
    spec.settings = {{"blur_passes", {"2", "5"}}};
    spec.hardware = {*glare::findSweepHardware("geforce4"), *glare::findSweepHardware("ideal")};
    spec.width = 160, spec.height = 90;
    spec.frames = 2;
    std::vector<glare::SweepRow> rows;
    std::string err;
    REQUIRE(glare::runSweep(spec, rows, err));
    INFO(err);
    REQUIRE(rows.size() == 4);  // 2 values x 2 hardware x 1 renderer
    int ideal = 0;
    for (const glare::SweepRow& r : rows) {
        CHECK(r.technique == "adaptive");
        CHECK(r.quality == "published");
        CHECK(r.scene == "box");
        CHECK(r.backend == "emu");
        CHECK(r.width == 160);
        CHECK(r.frames == 2);
        CHECK(r.msMin <= r.msMedian);
        CHECK(r.msMedian <= r.msMax);
        REQUIRE(r.swept.size() == 1);
        CHECK((r.swept[0].second == "2" || r.swept[0].second == "5"));
        CHECK(r.settings.at("blur_passes") == std::stod(r.swept[0].second));
        CHECK(!r.intendedError);  // adaptive states no math it approximates
        if (r.hardware == "ideal") {
            ++ideal;
            CHECK(r.precision == "ideal");
            CHECK(r.error.max == 0);
            CHECK(r.error.mean == 0);
            CHECK(r.error.overOnePercent == 0);
            CHECK(std::isinf(r.error.psnr));
        } else {
            CHECK(r.precision == "fx8");
            CHECK(std::isfinite(r.error.psnr) == (r.error.max > 0));
        }
    }
    CHECK(ideal == 2);
    checkFront(rows);
}

TEST_CASE("sweep: the pyramid and the glow carry their error against the intended math", "[sweep]") {
    glare::SweepSpec spec;
    spec.techniques = {glare::findTechnique("pyramid"), glare::findTechnique("glow")};
    spec.width = 96, spec.height = 64;
    spec.frames = 1;
    std::vector<glare::SweepRow> rows;
    std::string err;
    REQUIRE(glare::runSweep(spec, rows, err));
    REQUIRE(rows.size() == 2);
    for (const glare::SweepRow& r : rows) {
        INFO(r.technique);
        REQUIRE(r.intendedError);
        CHECK(r.intendedError->max <= 255);
    }
}

TEST_CASE("sweep: a setting none of the techniques has is refused, naming it", "[sweep]") {
    glare::SweepSpec spec;
    spec.techniques = {glare::findTechnique("quarter")};
    spec.settings = {{"radius", {"4", "8"}}};
    spec.width = 64, spec.height = 36;
    std::vector<glare::SweepRow> rows;
    std::string err;
    CHECK(!glare::runSweep(spec, rows, err));
    CHECK(err.find("radius") != std::string::npos);
    CHECK(rows.empty());
}

TEST_CASE("sweep: the Pareto front keeps the rows nothing beats on both time and error", "[sweep]") {
    std::vector<glare::SweepRow> rows = {row(10, 1.0, 5), row(20, 0.5, 3), row(30, 0.5, 2), row(30, 0.9, 9),
                                         row(5, 2.0, 8), row(40, 0.5, 2), row(15, 1.0, 5)};
    rows.back().technique = "pyramid";  // another group: it does not compete with the glow rows
    glare::markPareto(rows);
    CHECK(rows[0].pareto);   // 10 ms, 1.0
    CHECK(rows[1].pareto);   // 20 ms, 0.5/3
    CHECK(rows[2].pareto);   // 30 ms, the same mean, a lower max: the tie is broken by max
    CHECK(!rows[3].pareto);  // 30 ms, 0.9: the 20 ms row is faster and more accurate
    CHECK(rows[4].pareto);   // the fastest
    CHECK(rows[5].pareto);   // 40 ms, 0.5/2: slower than the 30 ms row but not less accurate: nothing beats it on both
    CHECK(rows[6].pareto);   // alone in its group
    checkFront({rows.begin(), rows.end() - 1});
}

TEST_CASE("intended math: uniform inputs give the kernels' DC gains", "[sweep]") {
    const glare::Technique& pyramid = *glare::findTechnique("pyramid");
    glare::Settings s = *glare::presetSettings(pyramid, "published");
    s["threshold"] = 0;
    s["strength"] = 0.25;
    s["size"] = 32;
    std::string why;
    // A sum of four normalised Gaussians: DC gain 4 (plain), 1 (normalised).
    std::optional<emu::FloatImage> out = glare::intendedResult(pyramid, s, uniform(64, 48, 0.1f), 0, why);
    REQUIRE(out);
    for (size_t i = 0; i < out->rgba.size(); i += 4) REQUIRE(out->rgba[i] == Approx(0.1 + 0.25 * 0.4).margin(1e-5));
    s["sum"] = 1;
    out = glare::intendedResult(pyramid, s, uniform(64, 48, 0.1f), 0, why);
    REQUIRE(out);
    CHECK(out->rgba[0] == Approx(0.1 + 0.25 * 0.1).margin(1e-5));

    // The glow: sources RGB × alpha through a normalised kernel, added with strength.
    const glare::Technique& glow = *glare::findTechnique("glow");
    glare::Settings g = *glare::presetSettings(glow, "published");
    g["strength"] = 0.5;
    out = glare::intendedResult(glow, g, uniform(64, 48, 0.2f, 0.5f), 0, why);
    REQUIRE(out);
    for (size_t i = 0; i < out->rgba.size(); i += 4) REQUIRE(out->rgba[i + 1] == Approx(0.2 + 0.5 * 0.2 * 0.5).margin(1e-5));
    // The source after-image doubles the sources (× (1 + decay)) from the second frame on.
    g["afterimage"] = 1;
    out = glare::intendedResult(glow, g, uniform(64, 48, 0.2f, 0.5f), 3, why);
    REQUIRE(out);
    CHECK(out->rgba[0] == Approx(0.2 + 0.5 * 0.1 * (1 + g.at("decay"))).margin(1e-5));
    // No stated result: feedback, and techniques without one.
    g["afterimage"] = 2;
    CHECK(!glare::intendedResult(glow, g, uniform(16, 16, 0.2f), 0, why));
    CHECK(why.find("feedback") != std::string::npos);
    CHECK(!glare::intendedResult(*glare::findTechnique("adaptive"), *glare::presetSettings(*glare::findTechnique("adaptive"), "published"),
                                 uniform(16, 16, 0.2f), 0, why));
}

TEST_CASE("intended math: a Gaussian kernel is normalised and has its sigma", "[sweep]") {
    const std::vector<double> k = glare::gaussianKernel(4.0, 20);
    REQUIRE(k.size() == 41);
    double sum = 0, var = 0;
    for (size_t i = 0; i < k.size(); ++i) {
        sum += k[i];
        var += k[i] * (double(i) - 20) * (double(i) - 20);
    }
    CHECK(sum == Approx(1.0));
    CHECK(std::sqrt(var) == Approx(4.0).epsilon(0.01));
    // A single bright pixel spreads into the kernel itself, in both directions.
    emu::FloatImage img = uniform(41, 41, 0.0f);
    img.rgba[(20 * 41 + 20) * 4] = 1.0f;
    glare::convolveRgb(img, k);
    CHECK(img.rgba[(20 * 41 + 20) * 4] == Approx(k[20] * k[20]));
    CHECK(img.rgba[(20 * 41 + 24) * 4] == Approx(k[24] * k[20]));
    CHECK(img.rgba[(24 * 41 + 20) * 4] == Approx(k[20] * k[24]));
}
