// The stress suite, GLARE.md §6 and robustness: each technique's quality metrics (temporal
// stability, fireflies, energy, halo shape, banding) on the emulated 1.1-class card, and checks
// that NaN, Inf, huge HDR values and 10 000 frames of adaptation leave every value in range
// (docs/stress.md). The §7 pitfalls are in glare/stress.cpp.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

#include "glare/stress.h"

namespace glare {

namespace {

constexpr double kPi = 3.14159265358979323846;

emu::FloatImage blank(uint32_t w, uint32_t h, float v) {
    emu::FloatImage img{w, h, {}};
    img.rgba.reserve(size_t(w) * h * 4);
    for (size_t i = 0; i < size_t(w) * h; ++i) img.rgba.insert(img.rgba.end(), {v, v, v, 1.0f});
    return img;
}

void put(emu::FloatImage& img, uint32_t x, uint32_t y, float v) {
    float* p = &img.rgba[(size_t(y) * img.width + x) * 4];
    p[0] = p[1] = p[2] = v;
}

Settings publishedOf(const Technique& t) { return *presetSettings(t, "published"); }

// The glare of one frame: output − scene, red channel, in levels (signed).
struct Frame {
    std::vector<int> glare;
    emu::RgbaImage output;
};

class Session {
public:
    Session(const StressOptions& o, const Technique& t, uint32_t side)
        : m_run(stressRunnerOptions(o, side, side)), m_t(t), m_settings(publishedOf(t)), m_side(side) {}
    Settings& settings() { return m_settings; }
    Runner& runner() { return m_run; }
    bool frame(const emu::FloatImage& img, int index, int count, Frame& f, std::string& error) {
        FrameResult r;
        if (!m_run.setImage(img, error) || !m_run.runFrame(m_t, m_settings, index, count, r, error)) return false;
        std::optional<emu::RgbaImage> out = m_run.readOutput(error), scene = m_run.readTexture(m_run.sceneTexture(), error);
        if (!out || !scene) return false;
        f.glare.resize(size_t(m_side) * m_side);
        for (size_t i = 0; i < f.glare.size(); ++i) f.glare[i] = int(out->rgba[i * 4]) - int(scene->rgba[i * 4]);
        f.output = std::move(*out);
        return true;
    }

private:
    Runner m_run;
    const Technique& m_t;
    Settings m_settings;
    uint32_t m_side;
};

double total(const std::vector<int>& v) { return double(std::accumulate(v.begin(), v.end(), 0L)); }

// The side of the technique's coarsest grid cell, in pixels of a side x side scene.
int coarsestCell(const Technique& t, const Settings& s, uint32_t side) {
    const std::string_view n = t.name();
    if (n == "adaptive" || n == "glow" || n == "quarter") return int(s.at("divisor"));
    if (n == "pyramid") return std::max(1, int(side) / std::max(1, int(s.at("size")) / 8));
    if (n == "sprites") return int(s.at("group"));
    return 8;
}

// r50, r90, the visibility radius and the anisotropy of a glare image around (cx, cy).
void halo(const std::vector<int>& g, uint32_t side, double cx, double cy, TechniqueMetrics& m) {
    struct P {
        double r;
        int v;
        int sector;
    };
    std::vector<P> ps;
    double vis = 0;
    for (uint32_t y = 0; y < side; ++y)
        for (uint32_t x = 0; x < side; ++x) {
            const int v = g[size_t(y) * side + x];
            if (v <= 0) continue;
            const double dx = double(x) - cx, dy = double(y) - cy, r = std::hypot(dx, dy);
            const int sector = int(std::floor((std::atan2(dy, dx) + kPi) / (2 * kPi) * 8)) & 7;
            ps.push_back({r, v, sector});
            vis = std::max(vis, r);
        }
    auto radiusHolding = [](std::vector<P> v, double share) {
        std::sort(v.begin(), v.end(), [](const P& a, const P& b) { return a.r < b.r; });
        double all = 0, acc = 0;
        for (const P& p : v) all += p.v;
        for (const P& p : v) {
            acc += p.v;
            if (acc >= share * all) return p.r;
        }
        return double(NAN);
    };
    m.r50 = radiusHolding(ps, 0.5);
    m.r90 = radiusHolding(ps, 0.9);
    m.visibilityRadius = vis;
    double lo = INFINITY, hi = 0;
    for (int s = 0; s < 8; ++s) {
        std::vector<P> sec;
        for (const P& p : ps)
            if (p.sector == s && p.r > 0) sec.push_back(p);
        const double r = sec.empty() ? 0 : radiusHolding(sec, 0.9);
        lo = std::min(lo, r);
        hi = std::max(hi, r);
    }
    m.anisotropy = lo > 0 ? hi / lo : NAN;
    // Banding along +x from the centre, to where the glare ends.
    std::set<int> levels;
    int step = 0, prev = -1;
    const uint32_t y = uint32_t(cy);
    for (uint32_t x = uint32_t(cx) + 1; x < side; ++x) {  // the source's own pixel is white: no room for glare
        const int v = g[size_t(y) * side + x];
        if (prev >= 0) step = std::max(step, std::abs(v - prev));
        levels.insert(v);
        prev = v;
        if (v <= 0) break;
    }
    m.bandLevels = int(levels.size());
    m.bandStep = step;
}

}  // namespace

bool stressMetrics(const StressOptions& o, const Technique& t, TechniqueMetrics& m, std::string& error) {
    const uint32_t side = o.size;
    m = {};
    m.technique = std::string(t.name());
    m.size = side;
    uint32_t cx = 0, cy = 0;
    if (!stressCapturedOffset(o, cx, cy, error)) return false;
    // Sources at a pixel the adaptive bright pass reads (other techniques read every pixel).
    const uint32_t px = side / 2 / 8 * 8 + cx, py = side / 2 / 8 * 8 + cy;
    Frame f;

    // Impulse: one white pixel on black; halo and banding of its glare. The energy measurements
    // (impulse, DC) set a technique's bright-pass threshold to 0 where it has one below 0.8 (the
    // sprites' sensors keep theirs): the glare's linear part, not what the threshold removes.
    auto linear = [&](Session& s) {
        if (t.name() != "sprites" && s.settings().count("threshold")) s.settings()["threshold"] = 0;
    };
    {
        Session s(o, t, side);
        linear(s);
        emu::FloatImage img = blank(side, side, 0);
        put(img, px, py, 1);
        if (!s.frame(img, 0, 1, f, error)) return false;
        m.impulseGain = total(f.glare) / 255.0;
        halo(f.glare, side, px, py, m);
    }
    // DC gain: a uniform 0.25 (room above it for a gain up to 4).
    {
        Session s(o, t, side);
        linear(s);
        if (!s.frame(blank(side, side, 0.25f), 0, 1, f, error)) return false;
        m.dcGain = total(f.glare) / (double(f.glare.size()) * std::nearbyint(0.25 * 255));
    }
    // Fireflies: a uniform 0.25 with one pixel 1000x the mean (the 8-bit scene holds it as 1.0).
    {
        Session a(o, t, side), b(o, t, side);
        emu::FloatImage img = blank(side, side, 0.25f);
        Frame without;
        if (!a.frame(img, 0, 1, without, error)) return false;
        put(img, px, py, 250.0f);
        if (!b.frame(img, 0, 1, f, error)) return false;
        const double all = total(f.glare);
        m.fireflyShare = all != 0 ? (all - total(without.glare)) / all : 0;
        m.fireflyArea = 0;
        for (size_t i = 0; i < f.glare.size(); ++i)
            if (std::abs(f.glare[i] - without.glare[i]) >= 1) ++m.fireflyArea;
    }
    // Temporal stability: a 2x2 white square moved by 1/8 pixel a frame (diagonally) through one
    // period of the coarsest grid, area-weighted into the pixels it covers.
    {
        Session s(o, t, side);
        const int cell = coarsestCell(t, s.settings(), side);
        m.stabilityFrames = 8 * cell;
        std::vector<double> energy, peak;
        for (int k = 0; k < m.stabilityFrames; ++k) {
            const double x0 = double(px) + k / 8.0, y0 = double(py) + k / 8.0;
            emu::FloatImage img = blank(side, side, 0);
            for (int y = int(y0); y <= int(y0) + 2; ++y)
                for (int x = int(x0); x <= int(x0) + 2; ++x) {
                    const double ox = std::max(0.0, std::min(x + 1.0, x0 + 2) - std::max(double(x), x0));
                    const double oy = std::max(0.0, std::min(y + 1.0, y0 + 2) - std::max(double(y), y0));
                    if (ox * oy > 0 && x < int(side) && y < int(side)) put(img, uint32_t(x), uint32_t(y), float(ox * oy));
                }
            if (!s.frame(img, k, m.stabilityFrames, f, error)) return false;
            energy.push_back(total(f.glare));
            peak.push_back(double(*std::max_element(f.glare.begin(), f.glare.end())));
        }
        auto spread = [](const std::vector<double>& v) {
            const double mean = std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
            return mean > 0 ? (*std::max_element(v.begin(), v.end()) - *std::min_element(v.begin(), v.end())) / mean : NAN;
        };
        m.stabilityEnergy = spread(energy);
        m.stabilityPeak = spread(peak);
    }
    return true;
}

// --- robustness -----------------------------------------------------------------------------

bool stressLongAdaptation(const StressOptions& o, int frames, RobustnessCheck& check, std::string& error) {
    // Four images in turn, 250 frames each: white, black, grey 0.35, grey 0.25.
    const uint32_t n = 8;
    const std::vector<emu::FloatImage> images = {blank(n, n, 1), blank(n, n, 0), blank(n, n, 0.35f), blank(n, n, 0.25f)};
    const int phase = 250;
    Settings s = publishedOf(*findTechnique("adaptive"));
    // Each image's target L: one frame with smoothing 1.
    std::vector<int> target;
    for (size_t i = 0; i < images.size(); ++i) {
        Settings once = s;
        once["smoothing"] = 1;
        once["start"] = 1;
        std::vector<int> l;
        if (!adaptationLevels(o, once, {images[i]}, {0}, l, error)) return false;
        target.push_back(l.at(0));
    }
    std::vector<int> order(static_cast<size_t>(frames));
    for (int f = 0; f < frames; ++f) order[size_t(f)] = (f / phase) % int(images.size());
    std::vector<int> levels;
    if (!adaptationLevels(o, s, images, order, levels, error)) return false;
    const double band = 0.5 * 255 / std::nearbyint(s.at("smoothing") * 255) + 1;
    int outOfRange = 0, stuck = 0;
    double worst = 0;
    for (int f = 0; f < frames; ++f) {
        const int v = levels[size_t(f)];
        if (v < 0 || v > 255) ++outOfRange;
        if ((f + 1) % phase == 0) {
            const double d = std::abs(v - target[size_t(order[size_t(f)])]);
            worst = std::max(worst, d);
            if (d > band) ++stuck;
        }
    }
    check.name = "adaptation_" + std::to_string(frames) + "_frames";
    check.pass = outOfRange == 0 && stuck == 0 && int(levels.size()) == frames;
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "%d frames (white, black, grey 0.35, grey 0.25, %d frames each): %d levels out of [0, 255], "
                  "%d phases ending more than %.1f levels from their target (worst %.0f)",
                  frames, phase, outOfRange, stuck, band, worst);
    check.detail = buf;
    return true;
}

bool stressRobustness(const StressOptions& o, std::vector<RobustnessCheck>& checks, std::string& error) {
    // Each technique on a 64x64 grey 0.25 with a 4x4 block of a special value: the run must succeed
    // and its output be that of the same block black or white (the 8-bit scene holds NaN and −Inf
    // as 0, +Inf and 10⁶ as 1): a special value never spreads further than a legal one.
    const uint32_t n = 64;
    struct Special {
        const char* name;
        float v;
    };
    const Special specials[] = {{"nan", NAN}, {"inf", INFINITY}, {"minus_inf", -INFINITY}, {"hdr_1e6", 1e6f}};
    for (const Technique* t : techniques()) {
        auto run = [&](float v, emu::RgbaImage& out) {
            Runner r(stressRunnerOptions(o, n, n));
            emu::FloatImage img = blank(n, n, 0.25f);
            for (uint32_t y = 30; y < 34; ++y)
                for (uint32_t x = 30; x < 34; ++x) put(img, x, y, v);
            FrameResult fr;
            if (!r.setImage(img, error) || !r.runFrame(*t, publishedOf(*t), 0, 1, fr, error)) return false;
            std::optional<emu::RgbaImage> o2 = r.readOutput(error);
            if (!o2) return false;
            out = std::move(*o2);
            return true;
        };
        emu::RgbaImage black, white;
        if (!run(0, black) || !run(1, white)) return false;
        for (const Special& sp : specials) {
            RobustnessCheck c;
            c.name = std::string(t->name()) + "_" + sp.name;
            emu::RgbaImage out;
            if (!run(sp.v, out)) {
                c.pass = false;
                c.detail = "the run failed: " + error;
                error.clear();
            } else {
                const bool asBlack = out.rgba == black.rgba, asWhite = out.rgba == white.rgba;
                c.pass = asBlack || asWhite;
                c.detail = asBlack   ? "output identical to a black block"
                           : asWhite ? "output identical to a white block"
                                     : "output differs from both a black and a white block";
            }
            checks.push_back(c);
        }
    }
    RobustnessCheck longRun;
    if (!stressLongAdaptation(o, o.adaptationFrames, longRun, error)) return false;
    checks.push_back(longRun);
    return true;
}

}  // namespace glare
