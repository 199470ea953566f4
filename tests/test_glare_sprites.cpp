// The glare sprites (glare/sprites.h, docs/glare/sprites.md): grouping keeps the total energy, the
// threaded sensor step gives the sprites of a plain one-pass reference bit for bit, the drawn
// glare buffer keeps its energy, and the luminance sum's threshold decides as luminance does.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "emu/fullscreen.h"
#include "emu/thread_pool.h"
#include "glare/runner.h"
#include "glare/sprites.h"
#include "glare_test_util.h"
#include "simd_levels.h"

using namespace glare;

using namespace glaretest;

TEST_CASE("sprites: grouping keeps the total glare energy", "[glare]") {
    // Scattered bright pixels (some adjacent) on black.
    const uint32_t w = 64, h = 48;
    std::vector<uint8_t> img(size_t(w) * h * 4, 0);
    auto set = [&](uint32_t x, uint32_t y, uint8_t r, uint8_t g, uint8_t b) {
        uint8_t* p = &img[(size_t(y) * w + x) * 4];
        p[0] = r, p[1] = g, p[2] = b, p[3] = 255;
    };
    for (uint32_t i = 0; i < 40; ++i) set((i * 37) % w, (i * 23 + i / 3) % h, 255, 240, uint8_t(200 + i));
    set(10, 10, 255, 255, 255);
    set(11, 10, 255, 255, 255);
    set(10, 11, 255, 255, 255);
    for (uint32_t y = 24; y < 32; ++y)
        for (uint32_t x = 40; x < 48; ++x) set(x, y, 255, 255, 255);  // an 8x8 block: a cluster
    SensorSettings base;
    base.strength = 0.1f;
    auto energy = [&](const std::vector<Sprite>& sprites) {
        std::array<double, 3> e{};
        for (const Sprite& s : sprites)
            for (int c = 0; c < 3; ++c) e[size_t(c)] += s.energy[c];
        return e;
    };
    base.group = 1;
    const auto single = senseSprites(img.data(), w, h, base);
    const auto e1 = energy(single);
    size_t clusters = 0;
    for (const Sprite& s : single) clusters += s.cluster;
    CHECK(clusters == 1);
    for (int n : {2, 3, 4, 5, 8}) {  // 3 and 5: groups straddle the cluster block
        SensorSettings s = base;
        s.group = n;
        const auto grouped = senseSprites(img.data(), w, h, s);
        CHECK(grouped.size() < single.size());
        const auto e = energy(grouped);
        for (int c = 0; c < 3; ++c) CHECK(e[size_t(c)] == Approx(e1[size_t(c)]).epsilon(1e-5));
    }
    // Without clusters, the 64 block pixels give 64 sprites with the same energy as the cluster.
    SensorSettings noClusters = base;
    noClusters.clusters = false;
    const auto e0 = energy(senseSprites(img.data(), w, h, noClusters));
    for (int c = 0; c < 3; ++c) CHECK(e0[size_t(c)] == Approx(e1[size_t(c)]).epsilon(1e-5));
}

namespace {

// The sensor step as one pass in raster order, written plainly: what the threaded senseSprites
// must reproduce sprite for sprite, bit for bit.
std::vector<Sprite> senseSpritesReference(const uint8_t* rgba, uint32_t width, uint32_t height,
                                          const SensorSettings& s) {
    auto luminance = [](const uint8_t* p) { return (0.30f * p[0] + 0.59f * p[1] + 0.11f * p[2]) / 255.0f; };
    std::vector<Sprite> out;
    const uint32_t n = uint32_t(std::max(s.group, 1));
    const uint32_t cw = (width + 7) / 8, ch = (height + 7) / 8;
    std::vector<uint8_t> clustered(size_t(cw) * ch, 0);
    auto addSprite = [&](uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1, bool cluster) {
        double sl = 0, sx = 0, sy = 0, e[3] = {0, 0, 0};
        for (uint32_t y = y0; y < y1; ++y)
            for (uint32_t x = x0; x < x1; ++x) {
                if (!cluster && s.clusters && clustered[size_t(y / 8) * cw + x / 8]) continue;
                const uint8_t* p = &rgba[(size_t(y) * width + x) * 4];
                const float l = luminance(p);
                if (l < s.threshold) continue;
                sl += l;
                sx += double(l) * x;
                sy += double(l) * y;
                for (int c = 0; c < 3; ++c) e[c] += p[c] / 255.0;
            }
        if (sl <= 0) return;
        Sprite sp;
        sp.x = float(sx / sl);
        sp.y = float(sy / sl);
        for (int c = 0; c < 3; ++c) sp.energy[c] = float(e[c] * s.strength);
        sp.radius = cluster ? 2 * s.radius : s.radius;
        sp.cluster = cluster;
        out.push_back(sp);
    };
    if (s.clusters)
        for (uint32_t by = 0; by < ch; ++by)
            for (uint32_t bx = 0; bx < cw; ++bx) {
                const uint32_t x0 = bx * 8, y0 = by * 8, x1 = std::min(x0 + 8, width), y1 = std::min(y0 + 8, height);
                uint32_t bright = 0;
                for (uint32_t y = y0; y < y1; ++y)
                    for (uint32_t x = x0; x < x1; ++x)
                        bright += luminance(&rgba[(size_t(y) * width + x) * 4]) >= s.threshold;
                if (bright * 10 >= 9 * (x1 - x0) * (y1 - y0)) {
                    clustered[size_t(by) * cw + bx] = 1;
                    addSprite(x0, y0, x1, y1, true);
                }
            }
    for (uint32_t y0 = 0; y0 < height; y0 += n)
        for (uint32_t x0 = 0; x0 < width; x0 += n)
            addSprite(x0, y0, std::min(x0 + n, width), std::min(y0 + n, height), false);
    return out;
}

// Bit for bit the same sprites, in the same order.
void sameSprites(const std::vector<Sprite>& got, const std::vector<Sprite>& want) {
    REQUIRE(got.size() == want.size());
    for (size_t i = 0; i < want.size(); ++i) {
        CHECK(std::memcmp(&got[i].x, &want[i].x, sizeof(float) * 2) == 0);
        CHECK(std::memcmp(got[i].energy, want[i].energy, sizeof want[i].energy) == 0);
        CHECK(got[i].radius == want[i].radius);
        CHECK(got[i].cluster == want[i].cluster);
    }
}

}  // namespace

TEST_CASE("sprites: the threaded sensor step gives the one-pass sensors' sprites exactly", "[glare]") {
    emu::ThreadPool one(1), three(3), eight(8);
    std::mt19937 rng(7);
    for (int round = 0; round < 24; ++round) {
        const uint32_t w = 1 + rng() % 300, h = 1 + rng() % 260;
        std::vector<uint8_t> img(size_t(w) * h * 4);
        const unsigned bright = rng() % 60;  // % of bright pixels, some in 8x8 blocks
        for (size_t i = 0; i < img.size(); ++i) img[i] = rng() % 100 < bright ? uint8_t(200 + rng() % 56) : uint8_t(rng() % 256);
        for (int b = 0; b < 4 && w >= 16 && h >= 16; ++b) {
            const uint32_t bx = rng() % (w - 8), by = rng() % (h - 8);
            for (uint32_t y = by; y < by + 8; ++y)
                for (uint32_t x = bx; x < bx + 8; ++x) std::memset(&img[(size_t(y) * w + x) * 4], 255, 4);
        }
        SensorSettings s;
        s.group = 1 + int(rng() % 6);
        s.clusters = rng() % 3 != 0;
        s.threshold = 0.3f + float(rng() % 60) / 100.0f;
        INFO(w << "x" << h << ", group " << s.group << ", clusters " << s.clusters << ", threshold " << s.threshold);
        const std::vector<Sprite> ref = senseSpritesReference(img.data(), w, h, s);
        // The same frame as D3D's b g r a words in rows with padding (what the read-back hands over).
        const size_t pitch = size_t(w) * 4 + 4 * (rng() % 5);
        std::vector<uint8_t> bgra(pitch * h, 0xEE);
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const uint8_t* p = &img[(size_t(y) * w + x) * 4];
                uint8_t* q = &bgra[y * pitch + size_t(x) * 4];
                q[0] = p[2], q[1] = p[1], q[2] = p[0], q[3] = p[3];
            }
        // On the calling thread and on pools of 1, 3 and 8 (the frame's bands split differently),
        // at every SIMD level (the sensor row's kernels).
        testutil::forEachSimdLevel([&](ps11::SimdLevel) {
            for (const std::vector<Sprite>& fast :
                 {senseSprites(img.data(), w, h, s), senseSprites(SensorFrame{bgra.data(), w, h, pitch, true}, s),
                  senseSprites(SensorFrame{bgra.data(), w, h, pitch, true, &one}, s),
                  senseSprites(SensorFrame{img.data(), w, h, size_t(w) * 4, false, &three}, s),
                  senseSprites(SensorFrame{bgra.data(), w, h, pitch, true, &eight}, s)}) {
                sameSprites(fast, ref);
            }
        });
        // The same frame as floats (a float render target), in rows with padding: byte i as
        // i/255 give or take 0.45/255, 255 as values past 1 or +inf, 0 as values below 0 or NaN.
        // The sensors see glare::frameBytes of it (the 8-bit frame readTexture gives).
        const size_t fpitch = (size_t(w) * 4 + 4 * (rng() % 3)) * sizeof(float);
        std::vector<float> values(fpitch / sizeof(float) * h, -7.0f);
        std::vector<uint8_t> seen(img.size());
        std::uniform_real_distribution<float> jitter(-0.45f, 0.45f);
        for (uint32_t y = 0; y < h; ++y) {
            float* row = values.data() + y * (fpitch / sizeof(float));
            for (size_t i = 0; i < size_t(w) * 4; ++i) {
                const uint8_t b = img[size_t(y) * w * 4 + i];
                float v = (float(b) + jitter(rng)) / 255.0f;
                if (b == 255 && rng() % 2) v = rng() % 2 ? 1.5f : std::numeric_limits<float>::infinity();
                if (b == 0 && rng() % 2) v = rng() % 2 ? -0.25f : std::numeric_limits<float>::quiet_NaN();
                row[i] = v;
            }
            frameBytes(row, size_t(w) * 4, &seen[size_t(y) * w * 4]);
        }
        REQUIRE(seen == img);  // the values say the frame's bytes
        for (emu::ThreadPool* pool : {static_cast<emu::ThreadPool*>(nullptr), &three}) {
            SensorFrame sf{nullptr, w, h, fpitch, true, pool};
            sf.values = values.data();
            sameSprites(senseSprites(sf, s), ref);
        }
    }
}

TEST_CASE("sprites: the drawn glare buffer keeps its energy when pixels are grouped", "[glare]") {
    // The same scattered lights drawn with N = 1 and N = 2 under the ideal profile (float glare
    // buffer): the buffers' sums agree within the bilinear footprint's rounding.
    const Technique& t = *findTechnique("sprites");
    // Sprites larger than the 128-texel glare image (radius 0.4·192 = 77 px) so bilinear sampling
    // magnifies it and the drawn sum does not depend on sub-pixel position; lights near the centre
    // so no sprite is clipped.
    const uint32_t w = 256, h = 192;
    emu::FloatImage img = uniform(w, h, 0, 0, 0);
    const uint32_t spots[][2] = {{120, 90}, {131, 97}, {100, 84}, {141, 101}};
    for (const auto& p : spots)
        for (uint32_t dy = 0; dy < 2; ++dy)
            for (uint32_t dx = 0; dx < 2; ++dx)
                for (int c = 0; c < 3; ++c) img.rgba[(size_t(p[1] + dy) * w + p[0] + dx) * 4 + size_t(c)] = 1;
    std::array<double, 2> totals{};
    for (int n : {1, 2}) {
        Runner run(options(w, h, ps11::Precision::Ideal));
        std::string err;
        REQUIRE(run.setImage(img, err));
        Settings s = preset("sprites");
        s["group"] = n;
        s["shrink"] = 0;
        s["strength"] = 15.0 / 255;  // vertex colours 15/255 (N = 1) and 60/255 (N = 2): both exact bytes
        s["radius"] = 0.4;
        double total = 0;
        PassGraph* graph = nullptr;
        FrameResult r;
        REQUIRE(run.runFrame(
            t, s, 0, 1, r, err,
            [&](uint32_t pass, bool after, std::string& e) {
                if (!after || graph->passes()[pass].info.name != "draw_sprites") return true;
                emu::Handle surface{};
                run.device().GetSurfaceLevel(graph->texture(graph->passes()[pass].writes[0]).device, 0, &surface);
                std::optional<emu::SurfacePixels> px = emu::readSurface(run.device(), surface, e);
                if (!px) return false;
                for (size_t i = 0; i < size_t(w) * h; ++i) {
                    float v;
                    std::memcpy(&v, &px->bytes[i * 16], 4);
                    total += v;
                }
                return true;
            },
            [&](PassGraph& g) { graph = &g; }));
        totals[size_t(n - 1)] = total;
    }
    CHECK(totals[0] > 0);
    CHECK(totals[1] == Approx(totals[0]).epsilon(0.03));
}

TEST_CASE("sprites: comparing the luminance sum with sensorSumThreshold is comparing luminance, for every colour",
          "[glare]") {
    // Every r, g, b byte triple against thresholds on and off the 8-bit grid, past the ends and NaN.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> thresholds = {0.8f, 0.5f, 0.31f, 1.0f / 255.0f, 1.0f, 0.0f, -0.25f, 1.5f, nan};
    // Some colours' own luminances and their float neighbours: the sums right at the threshold.
    std::mt19937 rng(2026);
    for (int k = 0; k < 4; ++k) {
        const float l = (0.30f * float(rng() % 256) + 0.59f * float(rng() % 256) + 0.11f * float(rng() % 256)) / 255.0f;
        for (const float t : {l, std::nextafter(l, 0.0f), std::nextafter(l, 2.0f)}) thresholds.push_back(t);
    }
    for (const float t : thresholds) {
        const float s = sensorSumThreshold(t);
        uint64_t mismatches = 0, fires = 0;
        for (int r = 0; r < 256; ++r)
            for (int g = 0; g < 256; ++g)
                for (int b = 0; b < 256; ++b) {
                    const float sum = 0.30f * float(r) + 0.59f * float(g) + 0.11f * float(b);
                    const bool byLuminance = sum / 255.0f >= t;
                    fires += byLuminance;
                    mismatches += byLuminance != (sum >= s);
                }
        INFO("threshold " << t << ", sum threshold " << s << ", colours firing " << fires);
        CHECK(mismatches == 0);
    }
    // The least such sum for many thresholds (division rounds monotonically, so the least float s
    // with s / 255 >= t is the whole rule): s reaches t, the float below it does not.
    uint64_t notLeast = 0;
    for (int k = 0; k < 200000; ++k) {
        const float l = (0.30f * float(rng() % 256) + 0.59f * float(rng() % 256) + 0.11f * float(rng() % 256)) / 255.0f;
        const float t = k % 3 == 0 ? l : k % 3 == 1 ? std::nextafter(l, 0.0f) : std::nextafter(l, 2.0f);
        const float s = sensorSumThreshold(t);
        notLeast += !(s / 255.0f >= t) || std::nextafter(s, -1.0f) / 255.0f >= t;
    }
    CHECK(notLeast == 0);
}
