#include "glare/sprites.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <thread>

#include "emu/format.h"
#include "emu/fullscreen.h"
#include "glare/passes.h"
#include "glare/runner.h"

namespace glare {

namespace {
constexpr double kPi = 3.14159265358979323846;
float luminance(const uint8_t* p) { return (0.30f * p[0] + 0.59f * p[1] + 0.11f * p[2]) / 255.0f; }
}  // namespace

std::vector<Sprite> senseSprites(const uint8_t* rgba, uint32_t width, uint32_t height, const SensorSettings& s) {
    const uint32_t n = uint32_t(std::max(s.group, 1));
    const size_t pixels = size_t(width) * height;
    // Workers: row bands of groups (at least 64 rows each), results joined in order, so the
    // sprites and every sum are those of one pass in raster order.
    const uint32_t groupRows = (height + n - 1) / n;
    const unsigned threads =
        std::max(1u, std::min({std::thread::hardware_concurrency(), 8u, groupRows * n / 64 + 1, groupRows}));
    auto inBands = [&](uint32_t rows, const std::function<void(uint32_t, uint32_t, unsigned)>& work) {
        std::vector<std::thread> pool;
        for (unsigned t = 1; t < threads; ++t)
            pool.emplace_back(work, uint32_t(uint64_t(rows) * t / threads), uint32_t(uint64_t(rows) * (t + 1) / threads), t);
        work(0, uint32_t(uint64_t(rows) / threads), 0);
        for (std::thread& th : pool) th.join();
    };
    // Whether each pixel's sensor fires (its luminance is taken again only where it does).
    std::vector<uint8_t> fires(pixels);
    inBands(height, [&](uint32_t y0, uint32_t y1, unsigned) {
        for (size_t i = size_t(y0) * width; i < size_t(y1) * width; ++i) fires[i] = luminance(&rgba[i * 4]) >= s.threshold;
    });
    // Cluster blocks first: 8x8 blocks at least 90 % bright.
    const uint32_t cw = (width + 7) / 8, ch = (height + 7) / 8;
    std::vector<uint8_t> clustered(size_t(cw) * ch, 0);
    auto sprite = [&](uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1, bool cluster, std::vector<Sprite>& out) {
        double sl = 0, sx = 0, sy = 0, e[3] = {0, 0, 0};
        for (uint32_t y = y0; y < y1; ++y)
            for (uint32_t x = x0; x < x1; ++x) {
                const size_t i = size_t(y) * width + x;
                if (!fires[i]) continue;
                // A group's pixels inside a cluster block belong to the cluster sprite only.
                if (!cluster && s.clusters && clustered[size_t(y / 8) * cw + x / 8]) continue;
                const float l = luminance(&rgba[i * 4]);
                sl += l;
                sx += double(l) * x;
                sy += double(l) * y;
                for (int c = 0; c < 3; ++c) e[c] += rgba[i * 4 + size_t(c)] / 255.0;
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
    if (s.clusters)
        for (uint32_t by = 0; by < ch; ++by)
            for (uint32_t bx = 0; bx < cw; ++bx) {
                const uint32_t x0 = bx * 8, y0 = by * 8, x1 = std::min(x0 + 8, width), y1 = std::min(y0 + 8, height);
                uint32_t bright = 0;
                for (uint32_t y = y0; y < y1; ++y)
                    for (uint32_t x = x0; x < x1; ++x) bright += fires[size_t(y) * width + x];
                if (bright * 10 >= 9 * (x1 - x0) * (y1 - y0)) {
                    clustered[size_t(by) * cw + bx] = 1;
                    sprite(x0, y0, x1, y1, true, out);
                }
            }
    std::vector<std::vector<Sprite>> bands(threads);
    inBands(groupRows, [&](uint32_t g0, uint32_t g1, unsigned t) {
        for (uint32_t y0 = g0 * n; y0 < std::min(g1 * n, height); y0 += n)
            for (uint32_t x0 = 0; x0 < width; x0 += n) {
                const uint32_t x1 = std::min(x0 + n, width), y1 = std::min(y0 + n, height);
                bool any = false;  // most groups of a frame are dark: one look at their mask
                for (uint32_t y = y0; y < y1 && !any; ++y)
                    for (uint32_t x = x0; x < x1 && !any; ++x) any = fires[size_t(y) * width + x];
                if (any) sprite(x0, y0, x1, y1, false, bands[t]);
            }
    });
    for (const std::vector<Sprite>& b : bands) out.insert(out.end(), b.begin(), b.end());
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
        const auto glare = std::make_shared<const std::vector<float>>(glareImage(imageSize, streaks));
        g.addPass(PassInfo{"glare_image", PassKind::DeviceSide, "",
                           "the precomputed glare image (streaks + halo), computed on the CPU and uploaded each frame"},
                  [&](PassBuilder& b) { b.write(image); },
                  [=](PassContext& c) {
                      const std::vector<float>& img = *glare;
                      emu::SurfacePixels px{imageSize, imageSize, D3DFMT_A8R8G8B8, 4, {}};
                      px.bytes.resize(img.size() * 4);
                      for (size_t i = 0; i < img.size(); ++i) {
                          const uint8_t v = uint8_t(std::lround(img[i] * 255));
                          px.bytes[i * 4 + 0] = px.bytes[i * 4 + 1] = px.bytes[i * 4 + 2] = v;
                          px.bytes[i * 4 + 3] = 255;
                      }
                      return emu::writeSurface(c.device, c.surface(image), px, c.error);
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
                      std::optional<emu::RgbaImage> img = runner->readTexture(c.texture(scene), c.error);
                      if (!img) return false;
                      *sprites = senseSprites(img->rgba.data(), img->width, img->height, ss);
                      c.stats.pixels += uint64_t(img->width) * img->height;
                      return true;
                  });

        const TextureId buffer = g.create("glare buffer", {sd.width, sd.height, fb.format});
        // The radial maximum of the glare image, for shrinking.
        const std::vector<float> radial = [&] {
            const std::vector<float>& img = *glare;
            std::vector<float> m(imageSize, 0);
            const float cc = (float(imageSize) - 1) / 2;
            for (uint32_t y = 0; y < imageSize; ++y)
                for (uint32_t x = 0; x < imageSize; ++x) {
                    const float r = std::hypot(float(x) - cc, float(y) - cc);
                    const size_t ri = std::min<size_t>(size_t(r), imageSize - 1);
                    m[ri] = std::max(m[ri], img[size_t(y) * imageSize + x]);
                }
            for (size_t i = imageSize - 1; i-- > 0;) m[i] = std::max(m[i], m[i + 1]);  // max beyond r
            return m;
        }();
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
                      return ok && c.check(d.SetTextureStageState(0, D3DTSS_COLORARG2, D3DTA_CURRENT)) &&
                             setBlend(c, Blend::None);
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
