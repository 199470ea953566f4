// The fx8 fast path (ps11/executor_fast.h) against the generic path, which is the reference
// (test_executor_reference.cpp checks it against docs/precision.md). The rounding steps of the
// kernel set of every SIMD level this CPU runs (SSE2, AVX2) are checked exhaustively over every
// input that does not saturate, and sampled beyond; then whole programs are compared pixel by
// pixel at every level: every arithmetic op over all operand pairs with each modifier, shift and
// _sat, random valid programs (co-issue, masks, selectors, 1_4 ranges) over spans of 1..kMaxSpan
// pixels, and textured programs.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "executed_texture_programs.h"
#include "executor_random_programs.h"
#include "simd_levels.h"
#include "ps11/assembler.h"
#include "ps11/executor.h"
#include "ps11/executor_fast.h"
#include "ps11/executor_presampled_internal.h"
#include "ps11/testfile.h"
#include "ps11/testfile_textures.h"
#include "ps11/texture_sampler.h"
#include "ps11/validator.h"

namespace {

using ps11::ExecPath;
using ps11::Precision;

// round_half_even(num / den), den > 0, written here from the definition.
int64_t rhe(int64_t num, int64_t den) {
    int64_t q = num / den, r = num % den;
    if (r < 0) r += den, q -= 1;
    if (2 * r > den || (2 * r == den && (q & 1))) ++q;
    return q;
}

// The kernel sets of the SIMD levels this CPU runs (none off x86-64).
std::vector<const ps11::exec::FastKernels*> kernelSets() {
    std::vector<const ps11::exec::FastKernels*> k;
    for (ps11::SimdLevel level : ps11::runnableSimdLevels())
        if (ps11::exec::fastKernels(level)) k.push_back(ps11::exec::fastKernels(level));
    return k;
}

struct Bounds {
    int16_t lo, hi;
};
// The write-step bounds the fast path meets: _sat, ±1 (1_1-1_3), ±8 (1_4), something between.
const Bounds kBounds[] = {{0, 255}, {-255, 255}, {-2040, 2040}, {-1020, 1020}};

// Checks roundProduct over p[0..n) (n a multiple of 16) against the exact definition.
int64_t checkProducts(const ps11::exec::FastKernels& k, const std::vector<int32_t>& p, int shift, bool half, Bounds b) {
    std::vector<int16_t> out(p.size());
    k.roundProduct(p.data(), out.data(), int(p.size()), shift, half, b.lo, b.hi);
    int64_t bad = 0;
    const int64_t den0 = half ? 255 : 1020;
    for (size_t i = 0; i < p.size(); ++i) {
        // n = round_half_even(P·2^s / (4G)), G = 255 (half: P'·2^s / G), then clamped.
        const int64_t num = shift > 0 ? int64_t(p[i]) << shift : int64_t(p[i]);
        const int64_t den = shift < 0 ? den0 << -shift : den0;
        const int64_t want = std::clamp<int64_t>(rhe(num, den), b.lo, b.hi);
        if (out[i] != want && bad++ < 5)
            FAIL_CHECK(k.name << (half ? " half" : "") << " product P=" << p[i] << " shift " << shift << ": " << out[i]
                              << " want " << want);
    }
    return bad;
}

}  // namespace

TEST_CASE("fast: product rounding is exact over every non-saturating numerator", "[fast]") {
    for (const auto* k : kernelSets()) {
        for (bool half : {false, true}) {
            // Largest |P| the fast path forms: dp4 of four k·k with |k| <= 4·2040 + 510 (half: k/2).
            const int64_t kMax = half ? 4335 : 8670;
            const int64_t kMaxP = 4 * kMax * kMax;
            for (int shift = -3; shift <= 3; ++shift) {
                // Every P whose result is within ±2043 (beyond it every bound saturates), in blocks.
                const int64_t den0 = half ? 255 : 1020;
                const int64_t den = shift < 0 ? den0 << -shift : den0;
                const int64_t lim = (2043 * den) >> std::max(shift, 0);
                std::vector<int32_t> p;
                int64_t bad = 0, checked = 0;
                for (const Bounds& b : {kBounds[2], kBounds[0]}) {
                    for (int64_t v = -lim; v <= lim;) {
                        p.clear();
                        for (; v <= lim && p.size() < (1u << 20); ++v) p.push_back(int32_t(v));
                        while (p.size() % 16) p.push_back(0);
                        bad += checkProducts(*k, p, shift, half, b);
                        checked += int64_t(p.size());
                    }
                }
                // Beyond: a dense stride and random numerators up to the largest |P|, all bounds.
                p.clear();
                std::mt19937 rng(uint32_t(77 + shift));
                for (int64_t v = -kMaxP; v <= kMaxP; v += 9973) p.push_back(int32_t(v));
                for (int i = 0; i < 200000; ++i)
                    p.push_back(int32_t(std::uniform_int_distribution<int64_t>(-kMaxP, kMaxP)(rng)));
                p.push_back(int32_t(kMaxP));
                p.push_back(int32_t(-kMaxP));
                while (p.size() % 16) p.push_back(int32_t(kMaxP));
                for (const Bounds& b : kBounds) bad += checkProducts(*k, p, shift, half, b);
                INFO(k->name << (half ? " half" : "") << " shift " << shift << ": " << checked
                             << " numerators exhaustively");
                CHECK(bad == 0);
                CHECK(checked >= 2 * lim);
            }
        }
    }
}

TEST_CASE("fast: linear rounding is exact over every reachable numerator", "[fast]") {
    // K = k0 ± k1 with |k| <= 8670: |K| <= 17340.
    std::vector<int16_t> kv;
    for (int v = -17344; v <= 17344; ++v) kv.push_back(int16_t(v));
    while (kv.size() % 16) kv.push_back(0);
    std::vector<int16_t> out(kv.size());
    for (const auto* k : kernelSets())
        for (int shift = -3; shift <= 3; ++shift)
            for (const Bounds& b : kBounds) {
                k->roundLinear(kv.data(), out.data(), int(kv.size()), shift, b.lo, b.hi);
                int bad = 0;
                for (size_t i = 0; i < kv.size(); ++i) {
                    // n = round_half_even(K·2^s / 2)
                    const int64_t num = shift > 0 ? int64_t(kv[i]) << shift : kv[i];
                    const int64_t den = shift < 0 ? int64_t(2) << -shift : 2;
                    const int64_t want = std::clamp<int64_t>(rhe(num, den), b.lo, b.hi);
                    if (out[i] != want && bad++ < 5)
                        FAIL_CHECK(k->name << " linear K=" << kv[i] << " shift " << shift << ": " << out[i] << " want "
                                           << want);
                }
                CHECK(bad == 0);
            }
}

TEST_CASE("fast: hand-computed ties and known values", "[fast]") {
    for (const auto* k : kernelSets()) {
        INFO(k->name);
        // mul 255·1 _d2 (k = 510, 2): P = 1020, 1020/2040 = ½ → 0 (even); 3·255·1 → 1.5 → 2.
        alignas(32) int32_t p[16] = {1020, 3060, 5100, -1020, -3060, 512, 508, 510, 1530, 0, 0, 0, 0, 0, 0, 0};
        alignas(32) int16_t out[16];
        k->roundProduct(p, out, 16, -1, false, -255, 255);
        CHECK(out[0] == 0);
        CHECK(out[1] == 2);
        CHECK(out[2] == 2);   // 2.5 → 2
        CHECK(out[3] == 0);   // −0.5 → 0
        CHECK(out[4] == -2);  // −1.5 → −2
        k->roundProduct(p, out, 16, 0, false, -255, 255);
        CHECK(out[5] == 1);  // 512/1020 > ½
        CHECK(out[6] == 0);  // 508/1020 < ½
        CHECK(out[7] == 0);  // 510/1020 = ½ → 0
        CHECK(out[8] == 2);  // 1530/1020 = 1.5 → 2
        // half: P'/255 — 127/255 < ½, 128/255 > ½; _d2: 255/510 = ½ → 0, 765/510 = 1.5 → 2.
        alignas(32) int32_t ph[16] = {127, 128, -127, -128, 255, 765, 1275, -255, 0, 0, 0, 0, 0, 0, 0, 0};
        k->roundProduct(ph, out, 16, 0, true, -255, 255);
        CHECK(out[0] == 0);
        CHECK(out[1] == 1);
        CHECK(out[2] == 0);
        CHECK(out[3] == -1);
        k->roundProduct(ph, out, 16, -1, true, -255, 255);
        CHECK(out[4] == 0);
        CHECK(out[5] == 2);
        CHECK(out[6] == 2);  // 2.5 → 2
        CHECK(out[7] == 0);  // −0.5 → 0
        alignas(32) int16_t kk[16] = {3, 5, -1, -3, 1, 7, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
        k->roundLinear(kk, out, 16, 0, -255, 255);  // K/2
        CHECK(out[0] == 2);
        CHECK(out[1] == 2);
        CHECK(out[2] == 0);
        CHECK(out[3] == -2);
        CHECK(out[4] == 0);
        CHECK(out[5] == 4);
    }
}

namespace {

std::unique_ptr<ps11::Executor> make(const std::string& text, Precision prec, float maxValue, ExecPath path) {
    ps11::Diagnostics diags;
    auto prog = ps11::parseAssembly(text, "fast.psh", {}, diags);
    REQUIRE(prog);
    if (!ps11::validate(*prog, diags)) FAIL(text << diags.formatAll());
    ps11::ExecutorOptions opt;
    opt.precision = prec;
    opt.maxValue = maxValue;
    opt.path = path;
    auto e = ps11::Executor::create(*prog, opt, diags);
    REQUIRE(e);
    return e;
}

// Per-pixel input arrays for up to count pixels.
struct Lanes {
    int count;
    std::vector<float> col[2][4], tc[8][4];
    explicit Lanes(int n) : count(n) {
        for (auto& v : col)
            for (auto& c : v) c.assign(size_t(n), 0.0f);
        for (auto& v : tc)
            for (auto& c : v) c.assign(size_t(n), 0.0f);
    }
    ps11::PixelInputs inputs(int off, int n) const {
        ps11::PixelInputs in;
        in.count = n;
        for (int i = 0; i < 2; ++i)
            for (int c = 0; c < 4; ++c) in.color[i][c] = col[i][c].data() + off;
        for (int i = 0; i < 8; ++i)
            for (int c = 0; c < 4; ++c) in.texcoord[i][c] = tc[i][c].data() + off;
        return in;
    }
};

struct Out {
    std::vector<float> color[4];
    std::vector<int32_t> grid[4];
    std::vector<uint8_t> killed;
    std::vector<float> depth;  // the program's own depth (texdepth, texm3x2depth); -3 where it writes none
    explicit Out(int n) {
        for (int c = 0; c < 4; ++c) color[c].assign(size_t(n), -7.0f), grid[c].assign(size_t(n), -77777);
        killed.assign(size_t(n), 9);
        depth.assign(size_t(n), -3.0f);
    }
    ps11::PixelOutputs outputs(int off) {
        ps11::PixelOutputs o;
        for (int c = 0; c < 4; ++c) o.color[c] = color[c].data() + off, o.grid[c] = grid[c].data() + off;
        o.killed = killed.data() + off;
        o.depth = depth.data() + off;
        return o;
    }
};

// Runs exec over all lanes in spans of `span` pixels.
void runAll(const ps11::Executor& e, const Lanes& l, Out& out, ps11::Sampler& s, int span) {
    for (int off = 0; off < l.count; off += span) {
        const int n = std::min(span, l.count - off);
        ps11::PixelInputs in = l.inputs(off, n);
        ps11::PixelOutputs o = out.outputs(off);
        e.run(in, s, o);
    }
}

// Compares two outputs bit for bit (grid, colour bits, killed); returns the mismatch count.
int64_t compare(const Out& a, const Out& b, int count, const std::string& what) {
    int64_t bad = 0;
    for (int i = 0; i < count; ++i) {
        bool ok = a.killed[size_t(i)] == b.killed[size_t(i)] &&
                  std::memcmp(&a.depth[size_t(i)], &b.depth[size_t(i)], sizeof(float)) == 0;
        for (int c = 0; c < 4; ++c) {
            ok = ok && a.grid[c][size_t(i)] == b.grid[c][size_t(i)];
            ok = ok && std::memcmp(&a.color[c][size_t(i)], &b.color[c][size_t(i)], sizeof(float)) == 0;
        }
        if (!ok && bad++ < 3) {
            FAIL_CHECK(what << "\npixel " << i << ": fast (" << a.grid[0][size_t(i)] << ", " << a.grid[1][size_t(i)]
                            << ", " << a.grid[2][size_t(i)] << ", " << a.grid[3][size_t(i)] << ") generic ("
                            << b.grid[0][size_t(i)] << ", " << b.grid[1][size_t(i)] << ", " << b.grid[2][size_t(i)]
                            << ", " << b.grid[3][size_t(i)] << ")");
        }
    }
    return bad;
}

// Runs text with the generic path, then with the fast path at every SIMD level this CPU runs,
// over the lanes; checks the fast path really runs with that level's kernels; returns mismatches.
int64_t diffPaths(const std::string& text, float maxValue, const Lanes& l, int span, ps11::Sampler& s,
                  const std::array<std::array<float, 4>, 8>* consts = nullptr, bool expectFast = true) {
    auto gen = make(text, Precision::Fx8, maxValue, ExecPath::Generic);
    CHECK(std::string(gen->pathName()) == "generic");
    auto set = [&](ps11::Executor& e) {
        if (consts)
            for (int i = 0; i < 8; ++i) e.setConstant(i, (*consts)[size_t(i)]);
    };
    set(*gen);
    Out want(l.count);
    runAll(*gen, l, want, s, span);
    int64_t bad = 0;
    auto fast = make(text, Precision::Fx8, maxValue, ExecPath::Auto);
    set(*fast);
    testutil::forEachSimdLevel([&](ps11::SimdLevel level) {
        const std::string name = fast->pathName();
        const ps11::exec::FastKernels* kernels = ps11::exec::fastKernels(level);
        if (kernels && expectFast)
            CHECK(name == kernels->name);
        else
            CHECK(name == "generic");  // or a build without x86 kernels: the generic path everywhere
        Out got(l.count);
        runAll(*fast, l, got, s, span);
        bad += compare(got, want, l.count, name + " span " + std::to_string(span) + "\n" + text);
    });
    return bad;
}

const char* kModSuffix[9][2] = {{"", ""},      {"-", ""},  {"", "_bias"}, {"-", "_bias"}, {"", "_bx2"},
                                {"-", "_bx2"}, {"1-", ""}, {"", "_x2"},   {"-", "_x2"}};
const char* kShiftName[7] = {"_d8", "_d4", "_d2", "", "_x2", "_x4", "_x8"};

}  // namespace

TEST_CASE("fast: every op over all operand pairs, each modifier, shift and _sat (ps_1_4, M = 1 and 8)", "[fast]") {
    // r0, r1, r2 loaded by texcrd from TC0..2 (exact grid values n/255 in ±M); pixel i carries
    // the pair (n0, n1) in each of r, g, b, so 3 pairs per pixel; n2 is pseudo-random.
    ps11::NullSampler sampler;
    struct OpDesc {
        const char* name;
        int srcs;
    };
    const OpDesc ops[] = {{"mov", 1}, {"add", 2}, {"sub", 2}, {"mul", 2}, {"mad", 3},
                          {"lrp", 3}, {"cnd", 3}, {"cmp", 3}, {"dp3", 2}};
    int64_t bad = 0, pixels = 0;
    for (float M : {1.0f, 8.0f}) {
        const int nMax = int(M) * 255;
        // M = 1: all 511² pairs; M = 8: n0 over all 4081 values, n1 with a stride of 127 plus its ends.
        std::vector<int> v1;
        for (int n = -nMax; n <= nMax; n += (M == 1.0f ? 1 : 127)) v1.push_back(n);
        v1.push_back(nMax);
        const int pairs = (2 * nMax + 1) * int(v1.size());
        const int count = (pairs + 2) / 3;
        Lanes l(count);
        std::mt19937 rng(1234);
        for (int p = 0; p < 3 * count; ++p) {
            const int pi = p % pairs;
            const int n0 = -nMax + pi / int(v1.size()), n1 = v1[size_t(pi % int(v1.size()))];
            const int n2 = std::uniform_int_distribution<int>(-nMax, nMax)(rng);
            const int lane = p / 3, comp = p % 3;
            l.tc[0][comp][size_t(lane)] = float(n0) / 255.0f;
            l.tc[1][comp][size_t(lane)] = float(n1) / 255.0f;
            l.tc[2][comp][size_t(lane)] = float(n2) / 255.0f;
        }
        struct Cfg {
            int mods[3];
            int shift;
            bool sat;
        };
        std::vector<Cfg> cfgs;
        for (int m = 0; m < 9; ++m)
            for (int s = 0; s < 3; ++s) {
                Cfg c{{0, 0, 0}, 0, false};
                c.mods[s] = m;
                cfgs.push_back(c);
            }
        for (int sh = -3; sh <= 3; ++sh)
            for (bool sat : {false, true}) cfgs.push_back(Cfg{{0, 0, 0}, sh, sat});
        cfgs.push_back(Cfg{{4, 6, 2}, 1, true});
        cfgs.push_back(Cfg{{5, 8, 3}, -2, false});
        for (const OpDesc& op : ops) {
            for (const Cfg& cfg : cfgs) {
                if (cfg.mods[1] && op.srcs < 2) continue;
                if (cfg.mods[2] && op.srcs < 3) continue;
                std::string text = "ps_1_4\ntexcrd r0.rgb, t0\ntexcrd r1.rgb, t1\ntexcrd r2.rgb, t2\n";
                text += std::string(op.name) + kShiftName[cfg.shift + 3] + (cfg.sat ? "_sat" : "") + " r0.rgb";
                for (int s = 0; s < op.srcs; ++s)
                    text += std::string(", ") + kModSuffix[cfg.mods[s]][0] + "r" + std::to_string(s) +
                            kModSuffix[cfg.mods[s]][1];
                text += "\n";
                bad += diffPaths(text, M, l, 256, sampler);
                pixels += count;
            }
        }
    }
    INFO(pixels << " pixels compared per path");
    CHECK(bad == 0);
}

TEST_CASE("fast: random valid programs over spans of 1..kMaxSpan pixels equal the generic path", "[fast]") {
    using namespace execrand;
    ps11::NullSampler sampler;
    struct Run {
        uint32_t seed;
        int minor;
        int programs;
    };
    const Run runs[] = {{0xfa570101u, 1, 300}, {0xfa570102u, 2, 150}, {0xfa570103u, 3, 150}, {0xfa570104u, 4, 400}};
    int64_t bad = 0;
    int fastRuns = 0, genericRuns = 0;
    for (const Run& r : runs) {
        Gen g(r.seed);
        int valid = 0, generated = 0;
        while (valid < r.programs && generated < r.programs * 40) {
            ++generated;
            Prog p = g.program(r.minor);
            const std::string text = progText(p);
            std::string err;
            if (!assemble(text, err)) continue;
            ++valid;
            // Maximum value: the default mostly; 1_4 also 1, 2, 4; now and then 16 (beyond int16:
            // the generic path must run).
            float M = 0;
            if (g.coin(0.2)) M = r.minor == 4 ? std::array<float, 4>{1, 2, 4, 16}[size_t(g.uni(0, 3))] : 2.0f;
            const bool fastExpected = M != 16.0f;
            const int count = g.coin(0.3) ? g.uni(1, 40) : g.uni(41, 700);
            const int span = g.coin(0.5) ? ps11::kMaxSpan : g.uni(1, ps11::kMaxSpan);  // (spans of more than one chunk too)
            Lanes l(count);
            for (int i = 0; i < count; ++i) {
                Inputs in = g.inputs();
                for (int v = 0; v < 2; ++v)
                    for (int c = 0; c < 4; ++c) l.col[v][c][size_t(i)] = in.color[v][c];
                for (int t = 0; t < 8; ++t)
                    for (int c = 0; c < 4; ++c) l.tc[t][c][size_t(i)] = in.tc[t][c];
            }
            std::array<std::array<float, 4>, 8> consts;
            Inputs ci = g.inputs();
            for (int i = 0; i < 8; ++i) consts[size_t(i)] = ci.consts[i];
            bad += diffPaths(text, M, l, span, sampler, &consts, fastExpected);
            (fastExpected ? fastRuns : genericRuns)++;
            if (bad > 10) break;
        }
        CHECK(valid >= r.programs / 2);
    }
    INFO(fastRuns << " programs on the fast path, " << genericRuns << " beyond it");
    CHECK(bad == 0);
    CHECK(fastRuns >= 700);
    CHECK(genericRuns >= 5);
}

TEST_CASE("uniform colour channels read once equal the same value in every lane", "[fast]") {
    // PixelInputs::uniformColor: a channel named uniform is read from its first float alone (the
    // arrays here hold that one float, so a read of another lane is out of bounds under ASan) and
    // must give what the value repeated in every lane gives, on the generic path and the fast
    // one at every SIMD level, in every profile; values outside [0, 1], NaN and ties included.
    using namespace execrand;
    ps11::NullSampler sampler;
    const float special[] = {std::nanf(""), -0.25f, 1.75f, 0.5f / 255.0f, 1.5f / 255.0f, 127.5f / 255.0f, 1.0f, 0.0f};
    int64_t bad = 0;
    int programs = 0;
    Gen g(0x0c0104e5u);
    for (int minor = 1; minor <= 4; ++minor) {
        int valid = 0;
        for (int tries = 0; valid < 40 && tries < 2000; ++tries) {
            const std::string text = progText(g.program(minor));
            std::string err;
            if (!assemble(text, err) || (text.find("v0") == std::string::npos && text.find("v1") == std::string::npos)) continue;
            ++valid;
            const int count = g.coin(0.5) ? g.uni(1, 40) : g.uni(41, 600);
            Lanes l(count);
            // One float per uniform channel; the others vary per lane.
            std::vector<float> one[2][4];
            uint8_t uniform = 0;
            for (int v = 0; v < 2; ++v)
                for (int c = 0; c < 4; ++c) {
                    const bool u = g.coin(0.7);
                    const float value = g.coin(0.3) ? special[size_t(g.uni(0, 7))] : g.inputs().color[v][c];
                    for (int i = 0; i < count; ++i) l.col[v][c][size_t(i)] = u ? value : g.inputs().color[v][c];
                    if (u) {
                        one[v][c].assign(1, value);
                        uniform = uint8_t(uniform | (1u << (4 * v + c)));
                    }
                }
            Inputs ci = g.inputs();
            for (const Precision prec : {Precision::Fx8, Precision::Fx12, Precision::Float, Precision::Ideal}) {
                for (const ExecPath path : {ExecPath::Generic, ExecPath::Auto}) {
                    auto e = make(text, prec, 0.0f, path);
                    for (int i = 0; i < 8; ++i) e->setConstant(i, ci.consts[i]);
                    testutil::forEachSimdLevel([&](ps11::SimdLevel) {
                        Out want(count), got(count);
                        runAll(*e, l, want, sampler, ps11::kMaxSpan);
                        for (int off = 0; off < count; off += ps11::kMaxSpan) {
                            ps11::PixelInputs in = l.inputs(off, std::min(ps11::kMaxSpan, count - off));
                            in.uniformColor = uniform;
                            for (int v = 0; v < 2; ++v)
                                for (int c = 0; c < 4; ++c)
                                    if (!one[v][c].empty()) in.color[v][c] = one[v][c].data();
                            ps11::PixelOutputs o = got.outputs(off);
                            e->run(in, sampler, o);
                        }
                        bad += compare(got, want, count,
                                       std::string(e->pathName()) + " profile " + std::to_string(int(prec)) + "\n" + text);
                    });
                }
            }
            ++programs;
            if (bad > 10) break;
        }
    }
    CHECK(programs >= 150);
    CHECK(bad == 0);
}

namespace {

std::shared_ptr<const ps11::Texture> smallTexture() {
    using namespace ps11;
    TextureDesc desc;
    desc.width = desc.height = 16;
    TextureLevel level;
    level.width = level.height = 16;
    level.texels.resize(256);
    for (uint32_t i = 0; i < 256; ++i) {
        const uint32_t h = (i * 2654435761u) >> 8;
        level.texels[i].bits = (h & 0xffffffu) | ((i * 37u & 0xffu) << 24);
    }
    desc.data.push_back(std::move(level));
    std::string error;
    auto t = textureFromDesc(desc, SignedDecode::Snorm, error);
    REQUIRE(t);
    return std::make_shared<const Texture>(std::move(*t));
}

// smallTexture() on stages 0-3, read LINEAR.
void bindSmallTexture(ps11::TextureSampler& sampler) {
    using namespace ps11;
    auto tex = smallTexture();
    SamplerDesc sd;
    sd.minFilter.value = sd.magFilter.value = Filter::Linear;
    for (int s = 0; s < 4; ++s) {
        sampler.bind(s, tex);
        sampler.setSamplerState(s, samplerStateFromDesc(sd));
    }
}

}  // namespace

TEST_CASE("fast: textured programs (tex, texld, texkill, dependent reads, texbem) equal the generic path", "[fast]") {
    using namespace ps11;
    TextureSampler sampler;
    bindSmallTexture(sampler);
    const char* programs[] = {
        "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c0, r0\nmad r0, t2, c0, r0\n"
        "mad r0, t3, c0, r0\n",
        "ps_1_1\ntex t0\nsub_sat r0, t0, c0\nmul_x4 r0, r0, r0\nmul r0, r0, c1\n",
        "ps_1_1\ntex t0\ntex t1\nmul r1, t1, c1\nmad r1, 1-t0, r1, t0\nlrp r0, c0.a, r1, t0\n",
        "ps_1_1\ntex t0\ntexkill t1\nmul r0.rgb, t0, v0\n+add r0.a, t0.a, -v1.a\n",
        "ps_1_1\ntex t0\ntexbem t1, t0\nmad r0, t1, c0, v0_bias\n",
        "ps_1_3\ntex t0\ntexreg2ar t1, t0\ndp3_sat r0, t0_bx2, t1_bx2\n",
        "ps_1_4\ntexld r0, t0\ntexcrd r1.rgb, t1\nmul r2, r0, c0\nphase\ntexld r3, r2\nmad_x2 r0.rgb, r3, r1, "
        "-r2\n+mov r0.a, r3.a\n",
        "ps_1_4\ntexld r1, t0\ntexkill r1\ncmp r0, r1_bias, c0, c1\n",
    };
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f);
    const int count = 300;
    Lanes l(count);
    for (int i = 0; i < count; ++i) {
        for (int v = 0; v < 2; ++v)
            for (int c = 0; c < 4; ++c) l.col[v][c][size_t(i)] = u(rng);
        for (int t = 0; t < 8; ++t)
            for (int c = 0; c < 4; ++c) l.tc[t][c][size_t(i)] = c == 3 ? 1.0f : u(rng);
    }
    // Colours the device should never send but the executor must treat alike: NaN, ±inf, −0.
    const float odd[] = {std::nanf(""), INFINITY, -INFINITY, -0.0f, 0.5f / 255.0f, 1.5f / 255.0f, 254.5f / 255.0f};
    for (int i = 0; i < count; i += 3)
        for (int v = 0; v < 2; ++v) l.col[v][(i / 3) % 4][size_t(i)] = odd[size_t((i / 3 + v) % 7)];
    std::array<std::array<float, 4>, 8> consts;
    for (auto& c : consts)
        for (float& f : c) f = u(rng) * 1.6f - 0.8f;
    int64_t bad = 0;
    for (const char* text : programs)
        for (int span : {256, 64, 37, 1}) bad += diffPaths(text, 0, l, span, sampler, &consts);
    CHECK(bad == 0);
}

namespace {

// A sampler for pre-sampled comparisons: stage s returns texels[s] at lane u (u is the lane's
// index), so run() sees the texels runPresampled's fill hands over.
struct LaneSampler final : ps11::Sampler {
    const std::vector<std::array<uint8_t, 4>>* texels[8] = {};
    int32_t scale = 1;  // grid steps per byte: 1 (fx8) or 16 (fx12)
    void sample(const ps11::SampleRequest& req, ps11::SampleResult& out) override {
        for (int i = 0; i < req.count; ++i) {
            const auto& t = (*texels[req.stage])[size_t(req.u[i])];
            for (int c = 0; c < 4; ++c) out.grid[c][i] = t[size_t(c)] * scale;
        }
    }
    bool hasTexture(int) const override { return true; }
};

}  // namespace

TEST_CASE("fast: pre-sampled runs equal run() with the same texels", "[fast]") {
    // runPresampled (the row paths' way in: presampledOps' sign analysis, product chains, the
    // complement factor; the generic path's runChunk with the taps filled in) against run() with
    // a sampler handing over the same 8-bit texels. Each
    // program runs pre-sampled (registers first poisoned by another program on the same thread)
    // under constants whose channels are 0 two times in five.
    using namespace ps11;
    const char* programs[] = {
        "ps_1_1\ntex t0\nmul r0, t0, c0\n",
        "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c1, r0\nmad r0, t2, c2, r0\n"
        "mad r0, t3, c3, r0\n",
        "ps_1_1\ntex t0\nmad r0, t0, c0, c1\n",
        "ps_1_1\ntex t0\nmul r0, t0, c0\nadd r0.a, r0.a, t0.a\n",
        "ps_1_1\ntex t0\ntex t1\nmul r0, t0, c0\ncnd r0, r0.a, t1, t0\n",
        "ps_1_1\ntex t0\ntex t1\ndp3 r0.rgb, t0, c0\n+mul r0.a, t1.a, c1.a\n",
        "ps_1_1\ntex t0\ntex t1\nmul r1, t0, c0\nmad r0, t1, c1, r1\n",
        "ps_1_1\ntex t0\ntex t1\nlrp r0, c0, t0, t1\n",
        "ps_1_1\ntex t0\ntex t1\nmul r0, 1-t0, c0\nmad r0, t1, c1, r0\n",
        "ps_1_1\ntex t0\nmul r0.rgb, t0, c0\n",
        "ps_1_4\ntexld r0, t0\ntexld r1, t1\nmul r0, r0, c0\nmad r0, r1, c1, r0\n",
        "ps_1_4\ntexld r2, t0\nmul r0, r2, c0\n",
    };
    auto poison = make("ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nadd r0, t0, t1\nadd r0, r0, t2\nadd r0, r0, t3\n",
                       Precision::Fx8, 0, ExecPath::Auto);
    TapPlan poisonPlan;
    REQUIRE(tapPlan(*poison, poisonPlan));
    std::mt19937 rng(4242);
    const int count = 200;
    std::vector<std::array<uint8_t, 4>> texels[8];
    for (auto& t : texels) t.resize(count);
    Lanes l(count);
    for (int i = 0; i < count; ++i)
        for (int t = 0; t < 8; ++t) l.tc[t][0][size_t(i)] = float(i);
    LaneSampler sampler;
    for (int s = 0; s < 8; ++s) sampler.texels[s] = &texels[s];
    struct Ctx {
        const std::vector<std::array<uint8_t, 4>>* texels;
        const TapPlan* plan;
        int base;
        std::vector<int32_t>* got;
        int scale;
    };
    const TapFill fill = [](void* p, int tap, int first, int n, int16_t* const dst[4]) {
        Ctx& x = *static_cast<Ctx*>(p);
        for (int c = 0; c < 4; ++c)
            for (int i = 0; i < n; ++i)
                dst[c][i] =
                    int16_t(x.texels[x.plan->stage[size_t(tap)]][size_t(x.base + first + i)][size_t(c)] * x.scale);
    };
    const ResultSink sink = [](void* p, int first, int n, const int16_t* const r0[4]) {
        Ctx& x = *static_cast<Ctx*>(p);
        for (int c = 0; c < 4; ++c)
            for (int i = 0; i < n; ++i) x.got[c][size_t(x.base + first + i)] = r0[c][i];
    };
    const TapFill poisonFill = [](void*, int, int, int n, int16_t* const dst[4]) {
        for (int c = 0; c < 4; ++c) std::fill_n(dst[c], n, int16_t(201));
    };
    const ResultSink ignore = [](void*, int, int, const int16_t* const[4]) {};
    int64_t bad = 0;
    int runs = 0;
    // The fast path's pre-sampled runs (fx8), and the generic path's: fx8 past the fast path's
    // grid, fx12 with MaxValue 8 (the radeon8500 class) and 0.5 (texels above M clamped).
    struct Config {
        Precision precision;
        float maxValue;
        ExecPath path;
    };
    const Config configs[] = {{Precision::Fx8, 0, ExecPath::Auto},
                              {Precision::Fx8, 16, ExecPath::Auto},
                              {Precision::Fx12, 8, ExecPath::Auto},
                              {Precision::Fx12, 0.5f, ExecPath::Auto}};
    for (const Config& cfg : configs)
        for (const char* text : programs) {
            INFO(text << "precision " << precisionName(cfg.precision) << ", MaxValue " << cfg.maxValue);
            const int scale = cfg.precision == Precision::Fx12 ? 16 : 1;
            sampler.scale = scale;
            auto gen = make(text, cfg.precision, cfg.maxValue, ExecPath::Generic);
            auto fast = make(text, cfg.precision, cfg.maxValue, cfg.path);
            TapPlan plan;
            REQUIRE(tapPlan(*fast, plan));
            for (int trial = 0; trial < 40; ++trial) {
                for (int i = 0; i < 8; ++i) {
                    std::array<float, 4> v;
                    for (float& f : v) f = rng() % 5 < 2 ? 0.0f : float(int(rng() % 511) - 255) / 255.0f;
                    gen->setConstant(i, v);
                    fast->setConstant(i, v);
                }
                for (auto& t : texels)
                    for (auto& px : t)
                        for (uint8_t& b : px) b = uint8_t(rng());
                Out want(count);
                runAll(*gen, l, want, sampler, 256);
                std::vector<int32_t> got[4];
                for (auto& g : got) g.assign(count, -9999);
                for (int off = 0; off < count; off += 64) {
                    const int n = std::min(64, count - off);
                    PixelInputs pin = l.inputs(off, n);
                    runPresampled(*poison, pin, poisonFill, ignore, nullptr);
                    Ctx ctx{texels, &plan, off, got, scale};
                    runPresampled(*fast, pin, fill, sink, &ctx);
                }
                ++runs;
                for (int c = 0; c < 4; ++c)
                    for (int i = 0; i < count; ++i)
                        if (got[c][size_t(i)] != want.grid[c][size_t(i)] && bad++ < 5)
                            FAIL_CHECK("trial " << trial << " lane " << i << " channel " << c << ": pre-sampled "
                                                << got[c][size_t(i)] << ", run() " << want.grid[c][size_t(i)]);
            }
        }
    INFO(runs << " runs");
    CHECK(bad == 0);
    CHECK(runs == 40 * int(std::size(programs) * std::size(configs)));
}

TEST_CASE("fast: pre-sampled runs that execute dependent reads equal run()", "[fast]") {
    // tapPlan(…, executes = true): plain reads come from `fill` (here the same sampler at their
    // lanes' coordinates), every other texture instruction (executed_texture_programs.h) runs as
    // run() runs it, with the sampler handed to runPresampled; killed lanes and the program's own
    // depth come back in PresampledRun::outputs. Fast path and generic path, fx8 and the
    // radeon8500 class's fx12, spans of 64, 37 and 50 lanes.
    using namespace ps11;
    TextureSampler sampler;
    bindSmallTexture(sampler);
    const auto& programs = executedprograms::kPrograms;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f);
    const int count = 300;
    Lanes l(count);
    for (int i = 0; i < count; ++i) {
        for (int v = 0; v < 2; ++v)
            for (int c = 0; c < 4; ++c) l.col[v][c][size_t(i)] = u(rng);
        for (int t = 0; t < 8; ++t)
            for (int c = 0; c < 4; ++c) l.tc[t][c][size_t(i)] = c == 3 ? u(rng) * 2.0f : u(rng);
    }
    struct Ctx {
        TextureSampler* sampler;
        const Lanes* lanes;
        const TapPlan* plan;
        int base;
        Precision precision;
        std::vector<int32_t>* got;
    };
    const TapFill fill = [](void* p, int tap, int first, int n, int16_t* const dst[4]) {
        Ctx& x = *static_cast<Ctx*>(p);
        const int set = x.plan->coordSet[size_t(tap)];
        SampleRequest req;
        req.stage = x.plan->stage[size_t(tap)];
        req.count = n;
        req.u = x.lanes->tc[set][0].data() + x.base + first;
        req.v = x.lanes->tc[set][1].data() + x.base + first;
        req.precision = x.precision;
        alignas(64) int32_t g[4][kMaxSpan];
        SampleResult out;
        for (int c = 0; c < 4; ++c) out.grid[c] = g[c];
        x.sampler->sample(req, out);
        for (int c = 0; c < 4; ++c)
            for (int i = 0; i < n; ++i) dst[c][i] = int16_t(g[c][i]);
    };
    const ResultSink sink = [](void* p, int first, int n, const int16_t* const r0[4]) {
        Ctx& x = *static_cast<Ctx*>(p);
        for (int c = 0; c < 4; ++c)
            for (int i = 0; i < n; ++i) x.got[c][size_t(x.base + first + i)] = r0[c][i];
    };
    struct Config {
        Precision precision;
        float maxValue;
        ExecPath path;
    };
    const Config configs[] = {{Precision::Fx8, 0, ExecPath::Auto},
                              {Precision::Fx8, 0, ExecPath::Generic},
                              {Precision::Fx8, 16, ExecPath::Auto},
                              {Precision::Fx12, 8, ExecPath::Auto}};
    std::array<std::array<float, 4>, 8> consts;
    for (auto& c : consts)
        for (float& f : c) f = u(rng) * 1.6f - 0.8f;
    int64_t bad = 0;
    int runs = 0;
    for (const Config& cfg : configs)
        for (const char* text : programs) {
            INFO(text << "precision " << precisionName(cfg.precision) << ", MaxValue " << cfg.maxValue << ", path "
                      << int(cfg.path));
            auto ref = make(text, cfg.precision, cfg.maxValue, ExecPath::Generic);
            auto e = make(text, cfg.precision, cfg.maxValue, cfg.path);
            for (int i = 0; i < 8; ++i) ref->setConstant(i, consts[size_t(i)]), e->setConstant(i, consts[size_t(i)]);
            TapPlan plan;
            CHECK_FALSE(tapPlan(*e, plan));  // (not without executes)
            REQUIRE(tapPlan(*e, plan, true));
            CHECK(plan.executes);
            const bool kills = std::string(text).find("texkill r") != std::string::npos;
            CHECK(plan.registerKills == kills);
            CHECK((plan.killSets != 0) == (std::string(text).find("texkill t") != std::string::npos));
            Out want(count);
            runAll(*ref, l, want, sampler, 256);
            const TapFill poisonFill = [](void*, int, int, int n, int16_t* const dst[4]) {
                for (int c = 0; c < 4; ++c) std::fill_n(dst[c], n, int16_t(201));  // (never asked for)
            };
            // Spans of 64 and 37 lanes; then every plain read left to the executor too
            // (PresampledRun::executedTaps: as a texture the caller does not filter).
            for (int span : {64, 37, 50}) {
                std::vector<int32_t> got[4];
                for (auto& g : got) g.assign(count, -9999);
                std::vector<uint8_t> killed(size_t(count), 7);
                std::vector<float> depth(size_t(count), -3.0f);
                for (int off = 0; off < count; off += span) {
                    const int n = std::min(span, count - off);
                    PixelInputs pin = l.inputs(off, n);
                    Ctx ctx{&sampler, &l, &plan, off, cfg.precision, got};
                    PixelOutputs more;
                    more.killed = killed.data() + off;
                    more.depth = depth.data() + off;
                    const uint8_t executed = span == 50 ? uint8_t((1u << plan.count) - 1) : uint8_t(0);
                    runPresampled(*e, pin, span == 50 ? poisonFill : fill, sink, &ctx, nullptr,
                                  PresampledRun{&sampler, &more, executed});
                }
                ++runs;
                // (A texkill of a coordinate set is the caller's, TapPlan::killSets: any of its
                // x, y, z below 0 kills the lane, as rowKills tests it.)
                for (int set = 0; set < 8; ++set)
                    if ((plan.killSets >> set) & 1)
                        for (int i = 0; i < count; ++i)
                            for (int k = 0; k < 3; ++k) killed[size_t(i)] |= uint8_t(l.tc[set][k][size_t(i)] < 0.0f);
                for (int c = 0; c < 4; ++c)
                    for (int i = 0; i < count; ++i)
                        if (got[c][size_t(i)] != want.grid[c][size_t(i)] && bad++ < 5)
                            FAIL_CHECK("span " << span << " lane " << i << " channel " << c << ": pre-sampled "
                                               << got[c][size_t(i)] << ", run() " << want.grid[c][size_t(i)]);
                int dead = 0, depths = 0;
                for (int i = 0; i < count; ++i) {
                    depths += want.depth[size_t(i)] != -3.0f;
                    if (std::memcmp(&depth[size_t(i)], &want.depth[size_t(i)], sizeof(float)) != 0 && bad++ < 5)
                        FAIL_CHECK("span " << span << " lane " << i << ": depth " << depth[size_t(i)] << ", run() "
                                           << want.depth[size_t(i)]);
                    dead += killed[size_t(i)];
                    if (killed[size_t(i)] != want.killed[size_t(i)] && bad++ < 5)
                        FAIL_CHECK("span " << span << " lane " << i << ": killed " << int(killed[size_t(i)])
                                           << ", run() " << int(want.killed[size_t(i)]));
                }
                if (kills || plan.killSets) CHECK((dead > 0 && dead < count));
                const bool depthProgram = std::string(text).find("depth") != std::string::npos;
                CHECK((depths > 0) == depthProgram);
            }
        }
    CHECK(bad == 0);
    CHECK(runs == 3 * int(std::size(programs) * std::size(configs)));
}

TEST_CASE("constants set again with the same bits keep their values; new bits take effect", "[fast]") {
    // A device sets c0…c7 before every draw; setConstant ignores a value equal bit for bit to the
    // one it holds. Runs after A, B, A again, A once more and −0 against 0 must each equal a fresh
    // executor given that constant once, on both paths and in every profile.
    using namespace ps11;
    const std::string text = "ps_1_1\nmad r0, v0, c0, c1\n";
    const std::array<float, 4> a{0.25f, 0.5f, 0.75f, 1.0f}, b{0.5f, 0.0f, 1.0f, 0.125f}, zero{0, 0, 0, 0},
        negZero{-0.0f, -0.0f, -0.0f, -0.0f}, bias{0.1f, 0.2f, 0.3f, 0.4f};
    Lanes l(40);
    for (int i = 0; i < l.count; ++i)
        for (int c = 0; c < 4; ++c) l.col[0][c][size_t(i)] = float((i * 7 + c * 13) % 41) / 40.0f;
    LaneSampler sampler;
    for (const Precision prec : {Precision::Fx8, Precision::Fx12, Precision::Float, Precision::Ideal})
        for (const ExecPath path : {ExecPath::Generic, ExecPath::Auto}) {
            INFO("profile " << int(prec) << ", path " << int(path));
            auto reused = make(text, prec, 0.0f, path);
            reused->setConstant(1, bias);
            for (const auto& c0 : {a, b, a, a, zero, negZero, b}) {
                reused->setConstant(0, c0);
                auto fresh = make(text, prec, 0.0f, path);
                fresh->setConstant(1, bias);
                fresh->setConstant(0, c0);
                Out want(l.count), got(l.count);
                runAll(*fresh, l, want, sampler, l.count);
                runAll(*reused, l, got, sampler, l.count);
                CHECK(compare(got, want, l.count, "c0 set again") == 0);
            }
        }
}

TEST_CASE("fast: chain rows equal pre-sampled runs over the same texel rows", "[fast]") {
    // runChainRow (a chain of products of taps and constants over a row's bytes as they lie)
    // against runPresampled fed each tap's filtered texel (the texel, or round_half_even of it and
    // the next one's mean), at every SIMD level, over runs of 1 to kMaxSpan pixels (the last
    // lanes of a run past the kernels' whole steps included), and which programs and constants
    // run as chain rows at all.
    using namespace ps11;
    struct Program {
        const char* text;
        bool chain;  // with every constant >= 0
        bool def = false;  // its constants are def'd (or it reads none): no negative API value reaches them
        float maxValue = 0;  // the profile's MaxValue (0: the version's)
    };
    const Program programs[] = {
        {"ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c1, r0\nmad r0, t2, c2, r0\n"
         "mad r0, t3, c3, r0\n",
         true},
        {"ps_1_1\ndef c0, 0.25, 0.25, 0.25, 0.25\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\n"
         "mad r0, t1, c0, r0\nmad r0, t2, c0, r0\nmad r0, t3, c0, r0\n",
         true, true},
        {"ps_1_1\ntex t0\ntex t1\nmul_sat r0, c2, t1\nmad_sat r0, c1, t0, r0\n", true},
        {"ps_1_4\ntexld r1, t0\ntexld r2, t1\nmul r0, r2, c0\nmad r0, r1, c1, r0\n", true, false, 1},
        // MaxValue 8: products past 16 bits (no chain of small products).
        {"ps_1_4\ntexld r1, t0\ntexld r2, t1\nmul r0, r2, c0\nmad r0, r1, c1, r0\n", false},
        {"ps_1_1\ntex t0\nmul r0, t0, c0\n", true},                                    // one product
        {"ps_1_1\ntex t0\nmul r0, c1, t0\n", true},                                    // the constant first
        {"ps_1_1\ntex t0\ntex t1\nmul r0, t0, t1\nmad r0, t1, c1, r0\n", true},        // a product of two taps
        {"ps_1_1\ntex t0\ntex t1\nmad r0, t1, 1-t0, t0\n", true, true},                      // Sousa's screen composite
        {"ps_1_1\ntex t0\ntex t1\nmad_sat r0, 1-t1, t0, t1\n", true, true},
        {"ps_1_1\ntex t0\nmul r0, 1-t0, c0\n", true},
        {"ps_1_1\ntex t0\ntex t1\nmad r0, c1, 1-t1, t0\n", true},                     // the constant first
        {"ps_1_1\ntex t0\ntex t1\nmad r0, t0, c0, c1\n", true},                       // a constant addend
        {"ps_1_1\ntex t0\ntex t1\nmad r0, t0, t0, t1\n", true, true},
        {"ps_1_1\ntex t0\nmul r0, t0, 1-c0\n", false},                                 // a complemented constant
        {"ps_1_1\ntex t0\ntex t1\nmad r0, t0, t1, -t1\n", false},                      // a negated addend
        {"ps_1_1\ntex t0\ntex t1\nmov r1, t1\nmad r0, t0, c0, r1\n", false},            // a register addend
        {"ps_1_1\ntex t0\ntex t1\nadd r0, t0, t1\n", false},                           // no product
        {"ps_1_1\ntex t0\nmul_x2 r0, t0, c0\n", false},                               // a shift
        {"ps_1_1\ntex t0\nmul r0.rgb, t0, c0\n", false},                              // not all of r0
        {"ps_1_1\ntex t0\ntex t1\nmul r0, t0, c0\nmad r0, t1, c1, t0\n", false},       // two products, not a chain
        {"ps_1_1\ntex t0\ntex t1\nmul r0, t0, c0.a\nmad r0, t1, c1, r0\n", false},     // a swizzle
        {"ps_1_1\ntex t0\ntex t1\nmul r1, t0, c0\nmad r1, t1, c1, r1\nmov r0, r1\n", false},  // not r0
        {"ps_1_1\ntex t0\ntex t1\nmul r0, t0, c0\nmad r0, t1, c1, r0\nadd r0, r0, c2\n", false},
        {"ps_1_1\ntex t0\ntex t1\nmul r0, t0, v0\nmad r0, t1, c1, r0\n", false},       // reads v0
    };
    std::mt19937 rng(3011);
    std::vector<std::array<uint8_t, 4>> texels[8];
    int chained = 0;
    testutil::forEachSimdLevel([&](SimdLevel) {
        for (const Program& prog : programs) {
            INFO(prog.text);
            auto fast = make(prog.text, Precision::Fx8, prog.maxValue, ExecPath::Auto);
            TapPlan plan;
            REQUIRE(tapPlan(*fast, plan));
            for (int trial = 0; trial < 12; ++trial) {
                const bool negative = trial % 4 == 3;
                for (int i = 0; i < 8; ++i) {
                    std::array<float, 4> v;
                    for (float& f : v) f = rng() % 5 < 1 ? 0.0f : float(rng() % 256) / 255.0f;
                    if (negative && i < 2) v[rng() % 4] = -float(1 + rng() % 255) / 255.0f;
                    fast->setConstant(i, v);
                }
                const bool want = prog.chain && (!negative || prog.def);
                REQUIRE(chainRows(*fast) == want);
                if (!want) continue;
                const int count = trial == 0 ? kMaxSpan : 1 + int(rng() % kMaxSpan);
                // Each tap's texel row (one texel more for its neighbour) and how it is read.
                std::vector<uint8_t> rows[8];
                ChainRowTap taps[8];
                for (int t = 0; t < plan.count; ++t) {
                    rows[t].resize(4 * size_t(count + 1));
                    for (uint8_t& b : rows[t]) b = uint8_t(rng() % 7 ? rng() : 255);
                    taps[t] = ChainRowTap{rows[t].data(), rng() % 2 == 0};
                    auto& tx = texels[plan.stage[size_t(t)]];
                    tx.resize(size_t(count));
                    for (int p = 0; p < count; ++p)
                        for (int c = 0; c < 4; ++c) {
                            const int k = 4 * p + kUnorm8Byte[c];
                            int v = rows[t][size_t(k)];
                            if (taps[t].halfX) {
                                const int sum = v + rows[t][size_t(k + 4)];
                                v = sum / 2 + (sum % 2 == 1 && (sum / 2) % 2 == 1 ? 1 : 0);
                            }
                            tx[size_t(p)][size_t(c)] = uint8_t(v);
                        }
                }
                // Stored plain, or-ed with X8R8G8B8's mask, or added (ONE/ONE) onto what the row holds.
                const int how = int(rng() % 3);
                const ChainRowStore store{how == 1 ? 0xff000000u : 0u, how == 2};
                std::vector<uint8_t> got(4 * size_t(count) + 64, 0xcd), before(4 * size_t(count));
                if (store.additive)
                    for (size_t i = 0; i < before.size(); ++i) got[i] = before[i] = uint8_t(rng() % 3 ? rng() % 64 : rng());
                runChainRow(*fast, taps, count, got.data(), store);
                // runPresampled over the same filtered texels.
                Lanes l(count);
                PixelInputs pin = l.inputs(0, count);
                struct Ctx {
                    const std::vector<std::array<uint8_t, 4>>* texels;
                    const TapPlan* plan;
                    std::vector<uint8_t>* want;
                } ctx{texels, &plan, nullptr};
                std::vector<uint8_t> expect(4 * size_t(count));
                ctx.want = &expect;
                const TapFill fill = [](void* p, int tap, int first, int n, int16_t* const dst[4]) {
                    const Ctx& x = *static_cast<const Ctx*>(p);
                    for (int c = 0; c < 4; ++c)
                        for (int i = 0; i < n; ++i)
                            dst[c][i] = x.texels[x.plan->stage[size_t(tap)]][size_t(first + i)][size_t(c)];
                };
                const ResultSink sink = [](void* p, int first, int n, const int16_t* const r0[4]) {
                    const Ctx& x = *static_cast<const Ctx*>(p);
                    for (int c = 0; c < 4; ++c)
                        for (int i = 0; i < n; ++i)
                            (*x.want)[4 * size_t(first + i) + size_t(kUnorm8Byte[c])] =
                                uint8_t(std::clamp<int>(r0[c][i], 0, 255));
                };
                runPresampled(*fast, pin, fill, sink, &ctx);
                for (size_t i = 0; i < expect.size(); ++i) {
                    if (i % 4 == size_t(kUnorm8Byte[3]) && how == 1) expect[i] = 255;
                    if (store.additive) expect[i] = uint8_t(std::min(255, expect[i] + before[i]));
                }
                ++chained;
                INFO("trial " << trial << ", " << count << " pixels");
                REQUIRE(std::equal(expect.begin(), expect.end(), got.begin()));
                // Nothing written past the run.
                CHECK(std::all_of(got.begin() + std::ptrdiff_t(expect.size()), got.end(),
                                  [](uint8_t b) { return b == 0xcd; }));
            }
        }
    });
    CHECK(chained > 0);
}

TEST_CASE("fast: the fast path applies to fx8 within int16 only", "[fast]") {
    if (!ps11::exec::fastKernels(ps11::SimdLevel::Baseline)) return;  // no x86 kernels in this build
    const std::string text = "ps_1_4\ntexcrd r0.rgb, t0\nmul r0.rgb, r0, r0\n";
    CHECK(std::string(make(text, Precision::Fx8, 0, ExecPath::Auto)->pathName()) != "generic");
    CHECK(std::string(make(text, Precision::Fx8, 8, ExecPath::Auto)->pathName()) != "generic");
    CHECK(std::string(make(text, Precision::Fx8, 9, ExecPath::Auto)->pathName()) == "generic");
    CHECK(std::string(make(text, Precision::Fx12, 0, ExecPath::Auto)->pathName()) == "generic");
    CHECK(std::string(make(text, Precision::Float, 0, ExecPath::Auto)->pathName()) == "generic");
    CHECK(std::string(make(text, Precision::Fx8, 0, ExecPath::Generic)->pathName()) == "generic");
    CHECK(std::string(
              make("ps_1_4\ntexld r1, t0\nbem r2.rg, c0, r1\nphase\nmov r0, r2.r\n", Precision::Fx8, 0, ExecPath::Auto)
                  ->pathName()) == "generic");
}
