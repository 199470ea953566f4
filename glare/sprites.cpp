#include "glare/sprites.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "emu/format.h"
#include "emu/fullscreen.h"
#include "emu/thread_pool.h"
#include "glare/passes.h"
#include "glare/runner.h"
#include "glare/sensors_kernels.h"

namespace glare {

namespace {
constexpr double kPi = 3.14159265358979323846;
// A pixel's luminance from its r, g, b bytes; the sensors fire where it reaches the threshold.
float luminance(uint32_t r, uint32_t g, uint32_t b) {
    return (0.30f * float(r) + 0.59f * float(g) + 0.11f * float(b)) / 255.0f;
}

// The number of bits set in each byte value (no POPCNT on the baseline x86-64).
constexpr auto kBitsSet = [] {
    std::array<uint8_t, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = uint8_t(std::popcount(unsigned(i)));
    return t;
}();

// The weighted sum luminance() divides by 255.
float luminanceSum(uint32_t r, uint32_t g, uint32_t b) { return 0.30f * float(r) + 0.59f * float(g) + 0.11f * float(b); }

}  // namespace

float sensorSumThreshold(float threshold) {
    if (std::isnan(threshold)) return std::numeric_limits<float>::infinity();
    if (threshold <= 0) return -std::numeric_limits<float>::infinity();
    float s = threshold * 255.0f;
    while (s / 255.0f >= threshold) s = std::nextafter(s, -std::numeric_limits<float>::infinity());
    while (s / 255.0f < threshold) s = std::nextafter(s, std::numeric_limits<float>::infinity());
    return s;
}

namespace {

// The Baseline level's sensor row (glare/sensors_kernels.h): four pixels at a time where SSE2 is
// there (every x86-64), the rest one by one with luminanceSum().
void fireRowBaseline(const uint8_t* row, uint32_t width, int rs, int bs, float sumAtLeast, uint64_t* fires) {
    uint32_t x = 0;
#if defined(__SSE2__)
    const __m128i m = _mm_set1_epi32(0xff);
    const __m128 kr = _mm_set1_ps(0.30f), kg = _mm_set1_ps(0.59f), kb = _mm_set1_ps(0.11f);
    const __m128 t = _mm_set1_ps(sumAtLeast);
    const __m128i sr = _mm_cvtsi32_si128(rs), sb = _mm_cvtsi32_si128(bs);
    for (; x + 4 <= width; x += 4) {
        const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + size_t(x) * 4));
        const __m128 r = _mm_cvtepi32_ps(_mm_and_si128(_mm_srl_epi32(w, sr), m));
        const __m128 g = _mm_cvtepi32_ps(_mm_and_si128(_mm_srli_epi32(w, 8), m));
        const __m128 b = _mm_cvtepi32_ps(_mm_and_si128(_mm_srl_epi32(w, sb), m));
        const __m128 l = _mm_add_ps(_mm_add_ps(_mm_mul_ps(kr, r), _mm_mul_ps(kg, g)), _mm_mul_ps(kb, b));
        fires[x / 64] |= uint64_t(_mm_movemask_ps(_mm_cmpge_ps(l, t))) << (x % 64);
    }
#endif
    for (; x < width; ++x) {
        const uint8_t* p = row + size_t(x) * 4;
        if (luminanceSum(p[rs / 8], p[1], p[bs / 8]) >= sumAtLeast) fires[x / 64] |= uint64_t(1) << (x % 64);
    }
}

// frameBytes at the Baseline level: 16 values a step where SSE2 is there, then one at a time.
void frameBytesBaseline(const float* in, size_t n, uint8_t* out) {
    size_t i = 0;
#if defined(__SSE2__)
    // max(v, 0) is 0 for NaN (MAXPS returns its second operand); the product and the sum round
    // as frameByte's float operations do, and the conversion truncates as its cast does.
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), k255 = _mm_set1_ps(255.0f), half = _mm_set1_ps(0.5f);
    auto ints = [&](const float* p) {
        const __m128 x = _mm_min_ps(_mm_max_ps(_mm_loadu_ps(p), zero), one);
        return _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(x, k255), half));
    };
    for (; i + 16 <= n; i += 16) {
        const __m128i lo = _mm_packs_epi32(ints(in + i), ints(in + i + 4));
        const __m128i hi = _mm_packs_epi32(ints(in + i + 8), ints(in + i + 12));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm_packus_epi16(lo, hi));
    }
#endif
    for (; i < n; ++i) out[i] = frameByte(in[i]);
}
}  // namespace

const SensorKernels baseline::kSensors{&fireRowBaseline, &frameBytesBaseline};

const SensorKernels& sensorKernels(ps11::SimdLevel level) {
#ifdef PS11_HAVE_AVX2
    return *ps11::simdTable(level, &baseline::kSensors, &avx2::kSensors);
#else
    (void)level;
    return baseline::kSensors;
#endif
}

namespace {

// Bands the sensors' steps split the frame into, at most (per-band results are kept per band).
constexpr unsigned kMaxSensorBands = 8;

// The workers of `pool` (null: the calling thread alone) over `rows` items of `rowsPerItem`
// pixel rows: bands of at least 64 pixel rows, at most kMaxSensorBands, the calling thread
// taking the first; `work(first, last, band)`. Callers join per-band results in band order, so the sprites and
// every sum are those of one pass in raster order.
void rowBands(uint32_t rows, uint32_t rowsPerItem, emu::ThreadPool* pool,
              const std::function<void(uint32_t, uint32_t, unsigned)>& work) {
    const unsigned wanted = pool ? unsigned(pool->size()) : 1u;
    const unsigned bands = std::max(1u, std::min({wanted, kMaxSensorBands, rows * rowsPerItem / 64 + 1, std::max(rows, 1u)}));
    if (bands == 1) {
        work(0, rows, 0);
        return;
    }
    pool->run(int(bands), [&](int t) {
        work(uint32_t(uint64_t(rows) * unsigned(t) / bands), uint32_t(uint64_t(rows) * unsigned(t + 1) / bands),
             unsigned(t));
    });
}

}  // namespace

std::vector<Sprite> senseSprites(const uint8_t* rgba, uint32_t width, uint32_t height, const SensorSettings& s) {
    return senseSprites(SensorFrame{rgba, width, height, size_t(width) * 4, false}, s);
}

std::vector<Sprite> senseSprites(const SensorFrame& f, const SensorSettings& s) {
    const uint32_t width = f.width, height = f.height;
    const uint32_t n = uint32_t(std::max(s.group, 1));
    // A float frame: the bytes of the rows where a sensor fires, tight, r g b a (the buffer is
    // the thread's, kept between frames: no fresh 8 MB a frame).
    static thread_local std::vector<uint8_t> fired8;
    const bool floats = f.values != nullptr;
    if (floats) fired8.resize(size_t(width) * height * 4);
    // (Workers name their own thread_local buffers: they write the rows through `kept`.)
    uint8_t* const kept = floats ? fired8.data() : nullptr;
    const uint8_t* const base = floats ? kept : f.data;
    const size_t pitch = floats ? size_t(width) * 4 : f.pitch;
    const bool bgra = !floats && f.bgra;
    const int rs = bgra ? 16 : 0, bs = bgra ? 0 : 16;  // bit shifts of r and b in a pixel's word
    auto pixel = [&](uint32_t x, uint32_t y) { return base + size_t(y) * pitch + size_t(x) * 4; };
    auto lum = [&](const uint8_t* p) { return luminance(p[rs / 8], p[1], p[bs / 8]); };
    const auto inBands = [&](uint32_t rows, uint32_t rowsPerItem,
                             const std::function<void(uint32_t, uint32_t, unsigned)>& work) {
        rowBands(rows, rowsPerItem, f.pool, work);
    };
    // Whether each pixel's sensor fires, one bit a pixel (its luminance is taken again only where
    // it does): dark stretches of a frame are skipped 64 pixels at a time.
    const size_t wpr = (size_t(width) + 63) / 64;
    std::vector<uint64_t> fires(wpr * height, 0);
    auto fired = [&](uint32_t x, uint32_t y) { return (fires[size_t(y) * wpr + x / 64] >> (x % 64)) & 1; };
    const float sumAtLeast = sensorSumThreshold(s.threshold);
    inBands(height, 1, [&](uint32_t y0, uint32_t y1, unsigned) {
        const SensorKernels& k = sensorKernels(ps11::simdLevel());
        if (!floats) {
            for (uint32_t y = y0; y < y1; ++y)
                k.fireRow(pixel(0, y), width, rs, bs, sumAtLeast, &fires[size_t(y) * wpr]);
            return;
        }
        static thread_local std::vector<uint8_t> row;
        row.resize(size_t(width) * 4);
        for (uint32_t y = y0; y < y1; ++y) {
            const float* in = reinterpret_cast<const float*>(reinterpret_cast<const uint8_t*>(f.values) + y * f.pitch);
            frameBytes(in, size_t(width) * 4, row.data());
            uint64_t* bits = &fires[size_t(y) * wpr];
            k.fireRow(row.data(), width, rs, bs, sumAtLeast, bits);
            if (std::any_of(bits, bits + wpr, [](uint64_t b) { return b != 0; }))
                std::memcpy(kept + size_t(y) * pitch, row.data(), size_t(width) * 4);
        }
    });
    // Cluster blocks first: 8x8 blocks at least 90 % bright.
    const uint32_t cw = (width + 7) / 8, ch = (height + 7) / 8;
    std::vector<uint8_t> clustered(size_t(cw) * ch, 0);
    auto sprite = [&](uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1, bool cluster, std::vector<Sprite>& out) {
        double sl = 0, sx = 0, sy = 0, e[3] = {0, 0, 0};
        for (uint32_t y = y0; y < y1; ++y)
            for (uint32_t x = x0; x < x1; ++x) {
                if (!fired(x, y)) continue;
                // A group's pixels inside a cluster block belong to the cluster sprite only.
                if (!cluster && s.clusters && clustered[size_t(y / 8) * cw + x / 8]) continue;
                const uint8_t* p = pixel(x, y);
                const float l = lum(p);
                sl += l;
                sx += double(l) * x;
                sy += double(l) * y;
                const uint8_t rgb[3] = {p[rs / 8], p[1], p[bs / 8]};
                for (int c = 0; c < 3; ++c) e[c] += rgb[c] / 255.0;
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
    std::vector<Sprite> out;
    std::vector<std::vector<Sprite>> bands(kMaxSensorBands);
    auto join = [&] {
        for (std::vector<Sprite>& b : bands) {
            out.insert(out.end(), b.begin(), b.end());
            b.clear();
        }
    };
    if (s.clusters) {
        inBands(ch, 8, [&](uint32_t b0, uint32_t b1, unsigned t) {
            for (uint32_t by = b0; by < b1; ++by) {
                const uint32_t y0 = by * 8, y1 = std::min(y0 + 8, height);
                for (uint32_t bx = 0; bx < cw; ++bx) {
                    const uint32_t x0 = bx * 8, x1 = std::min(x0 + 8, width);
                    uint32_t bright = 0;  // bits past the row's end are never set
                    for (uint32_t y = y0; y < y1; ++y)
                        bright += kBitsSet[(fires[size_t(y) * wpr + x0 / 64] >> (x0 % 64)) & 0xffu];
                    if (bright * 10 >= 9 * (x1 - x0) * (y1 - y0)) {
                        clustered[size_t(by) * cw + bx] = 1;
                        sprite(x0, y0, x1, y1, true, bands[t]);
                    }
                }
            }
        });
        join();
    }
    // Groups in raster order: per band of n rows, the groups holding a set bit of the rows' OR.
    const uint32_t groupRows = (height + n - 1) / n;
    inBands(groupRows, n, [&](uint32_t g0, uint32_t g1, unsigned t) {
        for (uint32_t y0 = g0 * n; y0 < std::min(g1 * n, height); y0 += n) {
            const uint32_t y1 = std::min(y0 + n, height);
            uint32_t next = 0;  // the first column of the next group not yet taken
            for (size_t k = 0; k < wpr; ++k) {
                uint64_t any = 0;
                for (uint32_t y = y0; y < y1; ++y) any |= fires[size_t(y) * wpr + k];
                while (any) {
                    const uint32_t x = uint32_t(k * 64) + uint32_t(std::countr_zero(any));
                    any &= any - 1;
                    if (x < next) continue;
                    const uint32_t x0 = x / n * n;
                    next = x0 + n;
                    sprite(x0, y0, std::min(next, width), y1, false, bands[t]);
                }
            }
        }
    });
    join();
    return out;
}

std::vector<float> glareImage(uint32_t size, int streaks) {
    std::vector<float> img(size_t(size) * size);
    const double c = (double(size) - 1) / 2;
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
            const double dx = (double(x) - c) / c, dy = (double(y) - c) / c;
            const double r = std::sqrt(dx * dx + dy * dy);
            if (r >= 1) continue;
            // The halo: a blur disc falling to 0 at the edge; the core: a sharp peak.
            const double fade = 1 - r;
            double v = 0.25 * std::exp(-r * r / 0.02) + 0.12 * fade * fade;
            // Streaks: thin rays whose width grows slowly with r, fading to the edge.
            const double a = std::atan2(dy, dx);
            for (int k = 0; k < streaks; ++k) {
                const double ak = kPi * double(k) / double(streaks) + 0.3;
                double d = std::fmod(std::abs(a - ak), kPi);
                d = std::min(d, kPi - d);  // a ray and its opposite
                const double across = d * r * double(size) / 2;  // distance to the ray in texels
                v += 0.6 * std::exp(-across * across / (0.6 + 2 * r)) * fade * fade;
            }
            img[size_t(y) * size + x] = float(v);
        }
    // Normalised: the brightest texel (the centre) is exactly 1.
    float peak = 0;
    for (float v : img) peak = std::max(peak, v);
    if (peak > 0)
        for (float& v : img) v /= peak;
    return img;
}

namespace {

// The largest value of a size×size image at each distance from its centre and beyond (index:
// the distance in texels, rounded down).
std::vector<float> radialMaximum(const std::vector<float>& img, uint32_t size) {
    std::vector<float> m(size, 0);
    const float cc = (float(size) - 1) / 2;
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
            const float r = std::hypot(float(x) - cc, float(y) - cc);
            const size_t ri = std::min<size_t>(size_t(r), size - 1);
            m[ri] = std::max(m[ri], img[size_t(y) * size + x]);
        }
    for (size_t i = size - 1; i-- > 0;) m[i] = std::max(m[i], m[i + 1]);  // max beyond r
    return m;
}

class Sprites final : public Technique {
public:
    std::string_view name() const override { return "sprites"; }
    std::string_view title() const override { return "Glare sprites (Ando et al., GRAPP 2006)"; }
    std::string_view scene() const override { return "lights"; }
    std::string_view summary() const override {
        return "sensors over bright pixels (device side: vertex texture fetch is not 1.1), N×N grouping, clusters, "
               "sprites of a glare image drawn additively";
    }
    const std::vector<ParamInfo>& params() const override {
        static const std::vector<ParamInfo> p = {
            {"threshold", "", "a sensor fires where luminance (0.30, 0.59, 0.11) >= threshold", 0, 1, {0.8, 0.8, 0.8, 0.8},
             {}, false},
            {"group", "pixels", "N: N x N pixels share one sprite (1 = a sensor per pixel, as the paper's base method)",
             1, 8, {4, 2, 1, 1}, {}, true},
            {"clusters", "", "8x8 blocks >= 90 % bright become one cluster sprite", 0, 1, {1, 1, 1, 1}, {"off", "on"},
             false},
            {"radius", "of height", "sprite radius as a fraction of the frame height", 0.005, 0.5,
             {0.04, 0.06, 0.08, 0.06}, {}, false},
            {"streaks", "", "radial streaks of the glare image (each a ray and its opposite)", 0, 16, {3, 4, 6, 4}, {},
             true},
            {"strength", "", "the glare image's peak per unit of pixel colour", 0, 1, {0.25, 0.25, 0.25, 0.25}, {}, false},
            {"shrink", "", "shrink sprites whose outer ring is below 0.5/255 (texture coordinates follow)", 0, 1,
             {1, 1, 1, 1}, {"off", "on"}, false},
        };
        return p;
    }

    void build(FrameBuild& fb) const override {
        PassGraph& g = fb.graph;
        const TextureDesc sd = fb.sceneDesc();
        SensorSettings ss;
        ss.threshold = float(fb.get("threshold"));
        ss.group = int(fb.get("group"));
        ss.clusters = fb.choice("clusters") == 1;
        ss.strength = float(fb.get("strength"));
        ss.radius = std::max(1.0f, float(fb.get("radius") * sd.height));
        const int streaks = int(fb.get("streaks"));
        const bool shrink = fb.choice("shrink") == 1;
        const uint32_t imageSize = 128;

        const TextureId image = g.create("glare image", {imageSize, imageSize, D3DFMT_A8R8G8B8});
        // The glare image and its radial maximum depend on the streaks only: made when they
        // change, kept on the runner (a few hundred thousand exp and atan2 a frame otherwise).
        struct GlareKept {
            int streaks = -1;
            std::vector<float> image;
            std::vector<float> radial;  // the radial maximum of the glare image, for shrinking
            // The image as uploaded (8-bit grey, alpha 255), in a surface of the runner's device
            // that each frame's upload copies from (a 64 KB StretchRect, which a fingerprint
            // covers: with reuse, the upload is reused while the surface and texture are as
            // they were).
            emu::Handle staging{};
            std::string error;  // why the surface could not be made
        };
        GlareKept& kept = fb.runner.kept<GlareKept>("sprites: glare image");
        if (kept.streaks != streaks) {
            kept.image = glareImage(imageSize, streaks);
            kept.radial = radialMaximum(kept.image, imageSize);
            kept.streaks = streaks;
            kept.error.clear();
            emu::Device& d = fb.runner.device();
            if (kept.staging != emu::Handle::Null) d.Release(kept.staging);
            kept.staging = emu::Handle::Null;
            D3DLOCKED_RECT lr{};
            if (d.CreateOffscreenPlainSurface(imageSize, imageSize, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &kept.staging) !=
                    D3D_OK ||
                d.LockRect(kept.staging, &lr, nullptr, 0) != D3D_OK) {
                kept.error = d.lastError().message;
                kept.streaks = -1;  // made again next frame
            } else {
                for (uint32_t y = 0; y < imageSize; ++y)
                    for (uint32_t x = 0; x < imageSize; ++x) {
                        const uint8_t v = uint8_t(std::lround(kept.image[size_t(y) * imageSize + x] * 255));
                        uint8_t* p = static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch) + size_t(x) * 4;
                        p[0] = p[1] = p[2] = v;
                        p[3] = 255;
                    }
                d.UnlockRect(kept.staging);
            }
        }
        const emu::Handle staging = kept.staging;
        const std::string stagingError = kept.error;
        const std::vector<float>& radial = kept.radial;
        g.addPass(PassInfo{"glare_image", PassKind::DeviceSide, "",
                           "the precomputed glare image (streaks + halo), computed on the CPU once and uploaded"},
                  [&](PassBuilder& b) { b.write(image); },
                  [=](PassContext& c) {
                      if (staging == emu::Handle::Null) {
                          c.error = "glare image: its surface could not be made: " + stagingError;
                          return false;
                      }
                      return c.check(c.device.StretchRect(staging, nullptr, c.surface(image), nullptr, D3DTEXF_POINT));
                  });

        auto sprites = std::make_shared<std::vector<Sprite>>();
        const TextureId list = g.createData("sprite list");
        const TextureId scene = fb.scene;
        Runner* runner = &fb.runner;
        g.addPass(PassInfo{"sensors", PassKind::DeviceSide, "",
                           "sensors need vertex texture fetch (vs_3_0), not 1.1: the frame is read back and sensed on the CPU"},
                  [&](PassBuilder& b) {
                      b.read(scene);
                      b.write(list);
                  },
                  [=](PassContext& c) {
                      // With reuse, a frame whose scene has the generation the last sensing read,
                      // under the same settings, has the same sprites: no read-back, no sensing.
                      struct Kept {
                          emu::Handle texture{};
                          uint64_t generation = 0;
                          SensorSettings settings;
                          std::vector<Sprite> sprites;
                          bool valid = false;
                      };
                      Kept& kept = runner->kept<Kept>("sprites: sensors");
                      const emu::Handle sceneTexture = c.texture(scene);
                      const uint64_t generation = c.device.contentGeneration(sceneTexture);
                      if (runner->reuses() && kept.valid && kept.texture == sceneTexture && kept.generation == generation &&
                          kept.settings == ss) {
                          *sprites = kept.sprites;
                          c.stats.reused = true;
                          return true;
                      }
                      kept.valid = false;
                      auto keep = [&] {
                          kept = Kept{sceneTexture, generation, ss, *sprites, true};
                          return true;
                      };
                      // 8-bit frames are sensed where they lie; float frames (ideal) through the
                      // runner's 8-bit conversion. On the renderer's workers (Runner::cpuPool).
                      emu::ThreadPool* const threads = &runner->cpuPool();
                      D3DSURFACE_DESC desc{};
                      if (!c.check(c.device.GetLevelDesc(c.texture(scene), 0, &desc))) return false;
                      if (desc.Format == D3DFMT_A8R8G8B8 || desc.Format == D3DFMT_X8R8G8B8)
                          return runner->readPixels(
                              c.texture(scene),
                              [&](const Runner::Pixels& px) {
                                  *sprites = senseSprites(
                                      SensorFrame{px.data, px.width, px.height, px.pitch, true, threads}, ss);
                                  c.stats.pixels += uint64_t(px.width) * px.height;
                                  return keep();
                              },
                              c.error);
                      if (desc.Format == D3DFMT_A32B32G32R32F)
                          return runner->readPixels(
                              c.texture(scene),
                              [&](const Runner::Pixels& px) {
                                  // The 8-bit frame readTexture would give, as the sensors read it.
                                  SensorFrame sf{nullptr, px.width, px.height, px.pitch, false, threads};
                                  sf.values = reinterpret_cast<const float*>(px.data);
                                  *sprites = senseSprites(sf, ss);
                                  c.stats.pixels += uint64_t(px.width) * px.height;
                                  return keep();
                              },
                              c.error);
                      static thread_local emu::RgbaImage img;  // kept: no fresh frame's worth every frame
                      if (!runner->readTexture(c.texture(scene), img, c.error)) return false;
                      *sprites = senseSprites(
                          SensorFrame{img.rgba.data(), img.width, img.height, size_t(img.width) * 4, false, threads}, ss);
                      c.stats.pixels += uint64_t(img.width) * img.height;
                      return keep();
                  });

        const TextureId buffer = g.create("glare buffer", {sd.width, sd.height, fb.format});
        g.addPass(PassInfo{"draw_sprites", PassKind::FixedFunction, "",
                           "one textured quad per sprite, glare image × vertex colour, additive (ONE, ONE)"},
                  [&](PassBuilder& b) {
                      b.read(list);
                      b.read(image);
                      b.write(buffer);
                  },
                  [=](PassContext& c) {
                      emu::Device& d = c.device;
                      if (!c.clear(buffer, 0) || !setBlend(c, Blend::Add) || !c.check(d.SetPixelShader(emu::Handle::Null)) ||
                          !bindTap(c, 0, Tap{image, {}, D3DTEXF_LINEAR}) ||
                          !c.check(d.SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_MODULATE)) ||
                          !c.check(d.SetTextureStageState(0, D3DTSS_COLORARG1, D3DTA_TEXTURE)) ||
                          !c.check(d.SetTextureStageState(0, D3DTSS_COLORARG2, D3DTA_DIFFUSE)) ||
                          !c.check(d.SetTextureStageState(1, D3DTSS_COLOROP, D3DTOP_DISABLE)) ||
                          !c.check(d.SetFVF(emu::kQuadFvf)))
                          return false;
                      std::vector<emu::QuadVertex> v;
                      const float half = float(imageSize) / 2;
                      for (const Sprite& s : *sprites) {
                          // A cluster sprite is twice the size (four times the area): its colour is a quarter.
                          const float area = s.cluster ? 4.0f : 1.0f;
                          const float peak = std::max({s.energy[0], s.energy[1], s.energy[2]}) / area;
                          // Colour above 1 does not fit a vertex colour: the sprite is drawn in layers.
                          const int layers = std::max(1, int(std::ceil(peak - 1e-6f)));
                          float rad = s.radius, uvHalf = 0.5f;
                          if (shrink) {
                              // The outermost texel ring still visible: peak·G(r) >= 0.5/255 per layer.
                              const float layerPeak = peak / float(layers);
                              size_t keep = 0;
                              for (size_t r = 0; r < radial.size(); ++r)
                                  if (layerPeak * radial[r] >= 0.5f / 255.0f) keep = r + 1;
                              const float frac = std::min(1.0f, (float(keep) + 1.0f) / half);
                              rad *= frac;
                              uvHalf *= frac;
                          }
                          if (rad <= 0.0f) continue;
                          DWORD colour = 0xff000000;
                          for (int ch = 0; ch < 3; ++ch) {
                              const float e = s.energy[ch] / float(layers) / area;
                              colour |= DWORD(std::lround(std::clamp(e, 0.0f, 1.0f) * 255)) << (16 - 8 * ch);
                          }
                          const emu::QuadCoords uv{0.5f - uvHalf, 0.5f - uvHalf, 0.5f + uvHalf, 0.5f + uvHalf};
                          const auto q = emu::halfPixelQuad(s.x + 0.5f - rad, s.y + 0.5f - rad, s.x + 0.5f + rad,
                                                            s.y + 0.5f + rad, {uv, uv, uv, uv}, colour);
                          for (int l = 0; l < layers; ++l)
                              for (int i : {0, 1, 2, 2, 1, 3}) v.push_back(q[size_t(i)]);
                      }
                      bool ok = true;
                      // One DrawPrimitiveUP per 4096 sprites' layers.
                      for (size_t first = 0; ok && first < v.size(); first += 6 * 4096) {
                          const size_t count = std::min<size_t>(v.size() - first, 6 * 4096);
                          ok = c.draw(D3DPT_TRIANGLELIST, UINT(count / 3), &v[first], sizeof(emu::QuadVertex));
                      }
                      return ok;
                  });
        addStretchPass(fb, "copy_scene", fb.scene, fb.output, D3DTEXF_POINT);
        addQuadPass(fb, "composite", "additive blend (ONE, ONE) of the glare buffer",
                    QuadPass{"scale.psh", fb.output, {texelTap(fb, buffer, 0, 0, D3DTEXF_POINT)}, {{0, {1, 1, 1, 0}}},
                             Blend::Add});
    }
};

}  // namespace

const Technique& spritesTechnique() {
    static const Sprites t;
    return t;
}

}  // namespace glare
