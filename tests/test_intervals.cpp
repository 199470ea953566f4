// The interval evaluator (ps11/intervals.h, docs/intervals.md) against the executor it bounds.
// Soundness: random programs (the arithmetic generator of executor_random_programs.h with some
// coordinate reads turned into texture lookups, the full generator of runner/random_program.h with
// every texture-address instruction, and small templates made to reach the constant and copy
// claims), random constants, stage states and input ranges, then random inputs inside those
// ranges (ends, zeros of both signs, NaN and infinities where a range admits them) run through
// ps11::Executor in fx8, fx12, float and ideal: every output lies in its interval, every claimed
// constant is the output bit for bit, every claimed copy is the lookup bit for bit, texkill and
// depth keep their bounds. The texel tiles (ps11/texture_tiles.h) those ranges come from are the
// exact ranges of their texels. Precision: the glare shaders' common cases give the constants and
// copies the renderer skips with.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "executor_random_programs.h"
#include "ps11/executor.h"
#include "ps11/intervals.h"
#include "ps11/texture.h"
#include "ps11/texture_tiles.h"
#include "texel_tiles_util.h"
#include "runner/random_program.h"

using namespace ps11;

namespace {

constexpr Precision kProfiles[] = {Precision::Fx8, Precision::Fx12, Precision::Float, Precision::Ideal};
constexpr int kLanes = 48;
constexpr double kInfD = std::numeric_limits<double>::infinity();

std::optional<Program> assembleValid(const std::string& text) {
    Diagnostics diags;
    auto prog = parseAssembly(text, "intervals.psh", {}, diags);
    if (!prog || !validate(*prog, diags)) return std::nullopt;
    return prog;
}

Program mustAssemble(const std::string& text) {
    Diagnostics diags;
    auto prog = parseAssembly(text, "intervals.psh", {}, diags);
    const bool valid = prog && validate(*prog, diags);
    INFO(text << diags.formatAll());
    REQUIRE(valid);
    return *prog;
}

std::string glareShader(const char* name) {
    std::ifstream in(std::string(PS11_SOURCE_DIR) + "/glare/shaders/" + name, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    REQUIRE(!ss.str().empty());
    return ss.str();
}

float ceilF(double d) {
    float f = float(d);
    return double(f) < d ? std::nextafter(f, INFINITY) : f;
}
float floorF(double d) {
    float f = float(d);
    return double(f) > d ? std::nextafter(f, -INFINITY) : f;
}
bool isNegZero(float v) { return v == 0.0f && std::signbit(v); }
uint32_t bitsOf(float v) {
    uint32_t b;
    std::memcpy(&b, &v, 4);
    return b;
}

// ---------------------------------------------------------------- random ranges and values
struct Rng {
    std::mt19937 rng;
    explicit Rng(uint32_t seed) : rng(seed) {}
    int uni(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }
    double real(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
    bool coin(double p) { return real(0, 1) < p; }

    // A range: unknown, a point, a grid-aligned or an arbitrary interval inside [a, b].
    ValueRange range(double a, double b) {
        const int kind = uni(0, 9);
        if (kind == 0) return ValueRange::any();
        auto val = [&] {
            switch (uni(0, 3)) {
                case 0:
                    return double(uni(int(a * 255), int(b * 255))) / 255.0;
                case 1:
                    return double(uni(int(a * 4), int(b * 4))) / 4.0;
                default:
                    return real(a, b);
            }
        };
        if (kind <= 3) {
            const double v = coin(0.6) ? std::array<double, 5>{0.0, 0.0, 1.0, 0.5, -1.0}[size_t(uni(0, 4))] : val();
            return coin(0.5) ? ValueRange::point(v) : ValueRange::between(v, v, coin(0.5));
        }
        double lo = val(), hi = val();
        if (lo > hi) std::swap(lo, hi);
        if (kind <= 5) {  // an end at 0
            if (coin(0.5))
                lo = 0, hi = std::max(hi, 0.0);
            else
                hi = 0, lo = std::min(lo, 0.0);
        }
        ValueRange r = ValueRange::between(lo, hi, coin(0.5));
        r.nan = coin(0.1);
        return r;
    }
    // A float inside the range (its ends, 0 of an admitted sign, grid values), or, for an unknown
    // range, anything including NaN and the infinities.
    float value(const ValueRange& r) {
        if (r.nan && coin(0.08)) return NAN;
        if (!std::isfinite(r.lo) || !std::isfinite(r.hi)) {
            switch (uni(0, 7)) {
                case 0:
                    return coin(0.5) ? INFINITY : -INFINITY;
                case 1:
                    return float(real(-1e30, 1e30));
                case 2:
                    return -0.0f;
                case 3:
                    return float(uni(-600, 600)) / 255.0f;
                default:
                    return float(real(-3, 3));
            }
        }
        const float lo = ceilF(r.lo), hi = floorF(r.hi);
        if (lo > hi) return float(r.lo);
        switch (uni(0, 7)) {
            case 0:
                return lo;
            case 1:
                return hi;
            case 2:
                if (lo <= 0 && hi >= 0) return r.negZero && coin(0.5) ? -0.0f : 0.0f;
                return lo;
            case 3: {
                const double g = coin(0.5) ? 255.0 : 4080.0;
                const double k = std::ceil(double(lo) * g), m = std::floor(double(hi) * g);
                if (k <= m) return float((k + double(uni(0, int(std::min(m - k, 1e6))))) / g);
                return hi;
            }
            default:
                return std::clamp(float(real(lo, hi)), lo, hi);
        }
    }
    // A grid integer inside the range (fx samplers hand back n, value n/G); unknown: anything
    // the executor's clamp has to cut.
    int32_t grid(const ValueRange& r, int32_t g, int32_t nMax) {
        if (!std::isfinite(r.lo) || !std::isfinite(r.hi)) return uni(-2 * nMax, 2 * nMax);
        const double lo = std::ceil(r.lo * g - 1e-9), hi = std::floor(r.hi * g + 1e-9);
        if (lo > hi) return int32_t(std::lround(r.lo * g));
        const int choice = uni(0, 3);
        if (choice == 0) return int32_t(lo);
        if (choice == 1) return int32_t(hi);
        return int32_t(lo + std::floor(real(0, hi - lo + 1 - 1e-9)));
    }
};

// Returns values inside each stage's range and records every request (one per sampling
// instruction: the runs here are one chunk).
class RangeSampler final : public Sampler {
public:
    RangeSampler(Rng& rng, const IntervalInputs& in, Precision prec, int32_t nMax)
        : m_rng(rng), m_in(in), m_prec(prec), m_nMax(nMax) {}
    struct Call {
        int stage;
        std::array<std::vector<int32_t>, 4> grid;
        std::array<std::vector<float>, 4> value;
    };
    std::vector<Call> calls;

    void sample(const SampleRequest& req, SampleResult& out) override {
        Call call{req.stage, {}, {}};
        const StageRange& sr = m_in.stages[size_t(req.stage)];
        for (int c = 0; c < 4; ++c)
            for (int i = 0; i < req.count; ++i) {
                const ValueRange& r = sr.value[size_t(c)];
                if (out.grid[c]) {
                    const int32_t n = m_rng.grid(r, gridScale(m_prec), m_nMax);
                    out.grid[c][i] = n;
                    call.grid[size_t(c)].push_back(n);
                }
                if (out.value[c]) {
                    const float v = m_rng.value(r);
                    out.value[c][i] = v;
                    call.value[size_t(c)].push_back(v);
                }
            }
        calls.push_back(std::move(call));
    }
    bool hasTexture(int) const override { return true; }

private:
    Rng& m_rng;
    const IntervalInputs& m_in;
    Precision m_prec;
    int32_t m_nMax;
};

struct Tally {
    int programs = 0, evaluations = 0, outputs = 0, constants = 0, copies = 0, channelCopies = 0, bounded = 0, neverKill = 0;
};

std::string rangeText(const ValueRange& r) {
    std::ostringstream o;
    o << "[" << r.lo << ", " << r.hi << "]" << (r.nan ? " nan" : "") << (r.negZero ? " -0" : "");
    return o.str();
}
std::string inputsText(const IntervalInputs& in) {
    std::ostringstream o;
    for (int s = 0; s < 4; ++s) {
        o << "stage " << s << (in.stages[size_t(s)].anyCoords ? " (any coords)" : "") << ":";
        for (const ValueRange& r : in.stages[size_t(s)].value) o << " " << rangeText(r);
        o << "\n";
    }
    for (int v = 0; v < 2; ++v) {
        o << "v" << v << ":";
        for (const ValueRange& r : in.color[size_t(v)]) o << " " << rangeText(r);
        o << "\n";
    }
    for (int t = 0; t < 6; ++t) {
        o << "TC" << t << ":";
        for (const ValueRange& r : in.texcoord[size_t(t)]) o << " " << rangeText(r);
        o << "\n";
    }
    return o.str();
}

// One program in one profile: several tiles of random ranges, each run over kLanes pixels.
void checkProgram(const Program& prog, const std::string& text, Precision prec, Rng& rng, Tally& tally) {
    const int minor = prog.version.minor;
    IntervalSetup setup;
    setup.options.precision = prec;
    if (rng.coin(0.3)) setup.options.coissuedCnd = CoissuedCnd::Sequential;  // geforce7's co-issued cnd
    if (rng.coin(0.15))
        setup.options.maxValue = minor == 4 ? std::array<float, 3>{1, 2, 4}[size_t(rng.uni(0, 2))] : 2.0f;
    if (!isFixedPoint(prec) && rng.coin(0.15)) setup.options.maxValue = 65504;  // the D3D9-class cards
    for (auto& c : setup.constants)
        for (float& f : c) {
            const int k = rng.uni(0, 9);
            f = k < 4    ? std::array<float, 4>{0.0f, 1.0f, -1.0f, 0.5f}[size_t(k)]
                : k == 4 ? -0.0f
                         : float(rng.real(-1.2, 1.2));
        }
    for (auto& c : setup.constants)  // whole registers of 0 or 1: the identities' other operand
        if (rng.coin(0.25)) c.fill(rng.coin(0.5) ? 0.0f : 1.0f);
    setup.stagesKnown = rng.coin(0.7);
    for (StageState& s : setup.stages) {
        for (float& m : s.bumpMat) m = rng.coin(0.3) ? 0.0f : float(rng.real(-2, 2));
        s.lumScale = float(rng.real(-2, 2));
        s.lumOffset = float(rng.real(-1, 1));
        s.clampLuminance = rng.coin(0.3);
    }
    Diagnostics diags;
    auto eval = IntervalEvaluator::create(prog, setup, diags);
    auto exec = Executor::create(prog, setup.options, diags);
    INFO(text << diags.formatAll());
    REQUIRE(eval);
    REQUIRE(exec);
    for (int i = 0; i < 8; ++i) exec->setConstant(i, setup.constants[size_t(i)]);
    for (int i = 0; i < kMaxTextureStages; ++i) exec->setStageState(i, setup.stages[size_t(i)]);
    const bool fx = isFixedPoint(prec);
    const int32_t nMax = eval->profile().nMax;
    ++tally.programs;

    for (int tile = 0; tile < 3; ++tile) {
        IntervalInputs in;
        for (StageRange& s : in.stages) {
            for (ValueRange& r : s.value) r = rng.coin(0.2) ? ValueRange::between(0, 1, false) : rng.range(-1.2, 1.2);
            // Whole tiles of one range (a zero tile, a constant one) as the renderer sees them.
            const int tileKind = rng.uni(0, 5);
            if (tileKind == 0) s.value.fill(rng.coin(0.5) ? ValueRange::point(0) : ValueRange::between(0, 0));
            if (tileKind == 1) s.value.fill(s.value[0]);
            s.anyCoords = rng.coin(0.5);
        }
        for (auto& v : in.color)
            for (ValueRange& r : v) r = rng.range(-0.3, 1.3);
        for (auto& t : in.texcoord)
            for (ValueRange& r : t) r = rng.range(-1.5, 1.5);
        IntervalResult res;
        eval->evaluate(in, res);
        ++tally.evaluations;

        float col[2][4][kLanes], tc[8][4][kLanes];
        PixelInputs pin;
        pin.count = kLanes;
        for (int l = 0; l < kLanes; ++l) {
            for (int v = 0; v < 2; ++v)
                for (int c = 0; c < 4; ++c) col[v][c][l] = rng.value(in.color[size_t(v)][size_t(c)]);
            for (int t = 0; t < 8; ++t)
                for (int c = 0; c < 4; ++c) tc[t][c][l] = rng.value(in.texcoord[size_t(t)][size_t(c)]);
        }
        for (int c = 0; c < 4; ++c) {
            for (int v = 0; v < 2; ++v) pin.color[v][c] = col[v][c];
            for (int t = 0; t < 8; ++t) pin.texcoord[t][c] = tc[t][c];
        }
        float outc[4][kLanes] = {}, depth[kLanes] = {};
        int32_t outg[4][kLanes] = {};
        uint8_t killed[kLanes] = {};
        PixelOutputs pout;
        for (int c = 0; c < 4; ++c) pout.color[c] = outc[c], pout.grid[c] = outg[c];
        pout.killed = killed;
        pout.depth = depth;
        RangeSampler sampler(rng, in, prec, nMax);
        exec->run(pin, sampler, pout);

        // The lookup a copy claim names: the k-th sampling instruction is the k-th request.
        // Per channel (copyMask) as well: the channels it names are that lookup's.
        int copyCall = -1;
        REQUIRE((res.copyStage >= 0) == (res.copyMask == 0xf));
        if (res.copyMask) {
            REQUIRE(res.channelCopyStage >= 0);
            if (res.copyStage >= 0) REQUIRE(res.copyInstruction == res.channelCopyInstruction);
            copyCall = 0;
            for (int i = 0; i < res.channelCopyInstruction; ++i)
                if (samplesStage(prog.instructions[size_t(i)].opcode())) ++copyCall;
            REQUIRE(copyCall < int(sampler.calls.size()));
            REQUIRE(sampler.calls[size_t(copyCall)].stage == res.channelCopyStage);
            tally.copies += res.copyMask == 0xf;
            tally.channelCopies += res.copyMask != 0xf;
        }
        tally.constants += res.constantColor();
        tally.neverKill += res.kill == KillRange::Never;
        for (int c = 0; c < 4; ++c) tally.bounded += res.color[size_t(c)].bounded;

        for (int l = 0; l < kLanes; ++l) {
            for (int c = 0; c < 4; ++c) {
                const ChannelInterval& ci = res.color[size_t(c)];
                const float v = outc[c][l];
                const int32_t n = outg[c][l];
                bool ok = true;
                if (fx) {
                    ok = n >= ci.gridLo && n <= ci.gridHi && (!ci.constant || n == ci.gridLo);
                    if (copyCall >= 0 && ((res.copyMask >> c) & 1))
                        ok = ok && n == sampler.calls[size_t(copyCall)].grid[size_t(c)][size_t(l)];
                } else {
                    if (v == v)
                        ok = double(v) >= ci.lo && double(v) <= ci.hi;
                    else
                        ok = !ci.bounded;
                    if (isNegZero(v)) ok = ok && ci.negZero;
                    if (ci.constant) ok = ok && bitsOf(v) == bitsOf(float(ci.lo));
                    if (copyCall >= 0 && ((res.copyMask >> c) & 1))
                        ok = ok && bitsOf(v) == bitsOf(sampler.calls[size_t(copyCall)].value[size_t(c)][size_t(l)]);
                }
                ++tally.outputs;
                if (!ok) {
                    FAIL_CHECK(precisionName(prec)
                               << " r0."
                               << "rgba"[c] << " lane " << l << ": executor " << (fx ? double(n) : double(v))
                               << (isNegZero(v) ? " (-0)" : "") << ", interval [" << (fx ? ci.gridLo : ci.lo) << ", "
                               << (fx ? ci.gridHi : ci.hi) << "] bounded " << ci.bounded << " negZero " << ci.negZero
                               << " constant " << ci.constant << " copy of stage " << res.copyStage << "\n"
                               << text << "\n"
                               << inputsText(in));
                    return;
                }
            }
            if ((res.kill == KillRange::Never && killed[l]) || (res.kill == KillRange::Always && !killed[l])) {
                FAIL_CHECK("texkill claim " << int(res.kill) << " wrong at lane " << l << "\n"
                                            << text << "\n"
                                            << inputsText(in));
                return;
            }
            if (res.writesDepth) {
                const float d = depth[l];
                if (!(d >= res.depth.lo && d <= res.depth.hi) ||
                    (res.depth.constant && bitsOf(d) != bitsOf(float(res.depth.lo)))) {
                    FAIL_CHECK("depth " << d << " outside [" << res.depth.lo << ", " << res.depth.hi << "]\n" << text);
                    return;
                }
            }
        }
    }
}

// The arithmetic generator's programs with some coordinate reads (texcoord, texcrd) turned into
// lookups of the same stage, so that sampled ranges flow through every arithmetic instruction.
std::string withLookups(const execrand::Prog& p, Rng& rng) {
    std::istringstream lines(execrand::progText(p));
    std::ostringstream out;
    std::string line;
    while (std::getline(lines, line)) {
        if (line.rfind("texcoord ", 0) == 0 && rng.coin(0.7)) line = "tex " + line.substr(9);
        if (line.rfind("texcrd ", 0) == 0 && rng.coin(0.7)) {
            // texcrd rD[.mask], tN.xyz|.xyw  ->  texld rD, tN
            const std::string dst = line.substr(7, line.find(',') - 7);
            const std::string reg = dst.substr(0, dst.find('.'));
            const size_t t = line.find(", t");
            line = "texld " + reg + ", t" + line.substr(t + 3, 1);
        }
        out << line << "\n";
    }
    return out.str();
}

// Small programs that reach the claims: exact identities over lookups, decided conditions,
// zero products.
const char* kTemplates[] = {
    "ps_1_1\ntex t0\ntex t1\nadd r0, t0, t1\n",
    "ps_1_1\ntex t0\ntex t1\nmov r0, t0\n",
    "ps_1_1\ntex t0\ntex t1\nmul r0, t0, t1\n",
    "ps_1_1\ntex t0\ntex t1\nmad r0, t1, c0, t0\n",
    "ps_1_1\ntex t0\ntex t1\nmad r0, t0, t1, c0\n",
    "ps_1_1\ntex t0\ntex t1\nsub_sat r0, t0, t1\n",
    "ps_1_1\ntex t0\ntex t1\nlrp r0, c0, t0, t1\n",
    "ps_1_1\ntex t0\ntex t1\nlrp r0, t1, t0, c1\n",
    "ps_1_1\ntex t0\ntex t1\nmov r0, t1\ncnd r0, r0.a, t0, t1\n",
    "ps_1_2\ntex t0\ntex t1\ncmp r0, t1, t0, c0\n",
    "ps_1_1\ntex t0\nsub_sat r0, t0, c0\nmul_x4 r0, r0, c1\n",
    "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\nmad r0, t1, c0, r0\nmad r0, t2, c0, r0\nmad r0, t3, c0, "
    "r0\n",
    "ps_1_1\ntex t0\ntex t1\nadd r0.rgb, t0, t1\n+mov r0.a, t0.a\n",
    "ps_1_4\ntexld r0, t0\ntexld r1, t1\nadd r0, r0, r1\n",
    "ps_1_4\ntexld r0, t0\ntexld r1, t1\nmad r0, r1, c0, r0\n",
    "ps_1_4\ntexld r1, t1\ntexcrd r2.rgb, t2\nphase\ntexld r0, t0\ntexld r2, r2\nmad r0.rgb, r2, r1, r0\n",
    "ps_1_1\ntex t0\ntexkill t1\nmov r0, t0\n",
    "ps_1_1\ntex t0\ntex t1\nmov r1, t0\nlrp r0, t1, t0, r1\n",
    "ps_1_1\ntex t0\ntex t1\nmov r0, t1\ncnd r0, r0.a, t0, t0\n",
    "ps_1_1\ntex t0\ntex t1\nmad r0, t1, 1-t0, t0\n",
    "ps_1_1\ndef c0, 0.30, 0.59, 0.11, 0.0\ntex t0\ntex t1\ndp3 r1, t0, c0\nadd r0, t0, t1\nlrp r0, r1, t0, r0\n",
    "ps_1_4\ntexld r1, t1\nbem_x2 r0.rg, c0, r1\nphase\nmov r0.ba, c1\n",
    "ps_1_4\ntexld r1, t1\nbem_d2_sat r0.rg, r1, c2\nphase\ntexld r2, t2\nadd r0.ba, r2, c1\n",
    "ps_1_1\ntex t0\ntexbeml t1, t0\nmov r0, t1\n",
    "ps_1_4\ntexcrd r0.rgb, t0_dw.xyw\nmov r0.a, r0.r\n",
    "ps_1_4\ntexld r0, t0_dw.xyw\ntexcrd r1.rgb, t1.xyw\nphase\ntexld r2, r1_dz\nmad r0.rgb, r2, c0, r0\n+mov r0.a, "
    "r2.b\n",
    "ps_1_3\ntex t0\ntexm3x2pad t1, t0\ntexm3x2depth t2, t0\nmov r0, t0\n",
};

TEST_CASE("intervals: every executor output lies in the evaluated bounds (random programs)", "[intervals]") {
    Tally tally;
    Rng rng(0x1a7e5);
    // The arithmetic generator, with lookups.
    for (int minor = 1; minor <= 4; ++minor) {
        execrand::Gen gen(1000u + uint32_t(minor));
        int made = 0;
        for (int attempt = 0; attempt < 4000 && made < 70; ++attempt) {
            const std::string text = withLookups(gen.program(minor), rng);
            auto prog = assembleValid(text);
            if (!prog) continue;
            ++made;
            for (Precision prec : kProfiles) checkProgram(*prog, text, prec, rng, tally);
        }
        CHECK(made == 70);
    }
    // Every texture-address instruction, bem, texkill, depth (runner/random_program.h).
    std::mt19937_64 caseRng(77);
    for (int i = 0; i < 160; ++i) {
        ps11test::RandomCaseOptions options;
        options.minor = 1 + i % 4;
        const std::string text = ps11test::randomCase(caseRng, options).shaderText();
        const Program prog = mustAssemble(text);
        for (Precision prec : kProfiles) checkProgram(prog, text, prec, rng, tally);
    }
    for (int round = 0; round < 40; ++round)
        for (const char* text : kTemplates) {
            const Program prog = mustAssemble(text);
            for (Precision prec : kProfiles) checkProgram(prog, text, prec, rng, tally);
        }
    INFO("programs " << tally.programs << ", evaluations " << tally.evaluations << ", outputs " << tally.outputs
                     << ", constant colours " << tally.constants << ", copies " << tally.copies << " (channels only " << tally.channelCopies << "), bounded channels "
                     << tally.bounded << ", never kill " << tally.neverKill);
    CHECK(tally.programs > 2000);
    CHECK(tally.constants > 100);
    CHECK(tally.copies > 100);
    CHECK(tally.channelCopies > 20);
}

}  // namespace

namespace {

using Consts = std::array<std::array<float, 4>, 8>;

IntervalResult evaluateOnce(const std::string& text, Precision prec, const Consts& consts, const IntervalInputs& in) {
    const Program prog = mustAssemble(text);
    IntervalSetup setup;
    setup.options.precision = prec;
    setup.constants = consts;
    Diagnostics diags;
    auto eval = IntervalEvaluator::create(prog, setup, diags);
    INFO(diags.formatAll());
    REQUIRE(eval);
    IntervalResult res;
    eval->evaluate(in, res);
    return res;
}

// A tile of an 8-bit texture: every channel in [lo, hi], never −0.0 or NaN.
StageRange unormTile(double lo, double hi) {
    StageRange s;
    s.value.fill(ValueRange::between(lo, hi, false));
    return s;
}

void requireConstant(const IntervalResult& r, std::array<double, 4> want, Precision prec) {
    INFO(precisionName(prec));
    for (int c = 0; c < 4; ++c) {
        INFO("r0."
             << "rgba"[c] << " [" << r.color[size_t(c)].lo << ", " << r.color[size_t(c)].hi << "]");
        CHECK(r.color[size_t(c)].constant);
        CHECK(r.color[size_t(c)].lo == Approx(want[size_t(c)]).margin(1e-6));
    }
    CHECK(r.constantColor());
}

}  // namespace

TEST_CASE("intervals: a bright pass over a tile below its threshold is the constant 0", "[intervals]") {
    // bright_threshold.psh: c0 = (t, t, t, 0), c1 = (s/4, s/4, s/4, 1), s = 1/(1 − t), t = 0.4.
    const float t = 0.4f, s4 = 1.0f / (1.0f - t) / 4.0f;
    Consts k{};
    k[0] = {t, t, t, 0};
    k[1] = {s4, s4, s4, 1};
    const std::string shader = glareShader("bright_threshold.psh");
    for (Precision prec : kProfiles) {
        IntervalInputs in;
        in.stages[0] = unormTile(0, 0.39);
        requireConstant(evaluateOnce(shader, prec, k, in), {0, 0, 0, 1}, prec);
        in.stages[0] = unormTile(0, 102.0 / 255.0);  // the maximum exactly at the threshold
        requireConstant(evaluateOnce(shader, prec, k, in), {0, 0, 0, 1}, prec);
        in.stages[0] = unormTile(0.2, 0.6);  // partly above: shaded
        const IntervalResult above = evaluateOnce(shader, prec, k, in);
        CHECK_FALSE(above.color[0].constant);
        CHECK(above.color[0].lo == 0);
        CHECK(above.color[0].hi == Approx(0.2 / 0.6).margin(0.01));
    }
    // Thresholding all four channels: sub_sat, then mul_x4.
    k[0].fill(t);
    k[1].fill(s4);
    for (Precision prec : kProfiles) {
        IntervalInputs in;
        in.stages[0] = unormTile(0, 0.35);
        requireConstant(evaluateOnce("ps_1_1\ntex t0\nsub_sat r0, t0, c0\nmul_x4 r0, r0, c1\n", prec, k, in),
                        {0, 0, 0, 0}, prec);
    }
}

TEST_CASE("intervals: the adaptive bright pass is constant over dark tiles, whatever the adapted amount",
          "[intervals]") {
    // adaptive_bright.psh: c0 = (t, t, t, 0) with t = 0.4, c1 = (w, w, w, 1) with w = 1.
    Consts k{};
    k[0] = {0.4f, 0.4f, 0.4f, 0};
    k[1] = {1, 1, 1, 1};
    for (Precision prec : kProfiles) {
        IntervalInputs in;
        in.stages[0] = unormTile(0, 0.3);
        in.stages[1] = unormTile(0, 1);
        requireConstant(evaluateOnce(glareShader("adaptive_bright.psh"), prec, k, in), {0, 0, 0, 1}, prec);
    }
}

TEST_CASE("intervals: an additive composite over a zero glare tile is a copy of the scene", "[intervals]") {
    const std::string shader = glareShader("composite_add.psh");
    for (Precision prec : kProfiles) {
        INFO(precisionName(prec));
        IntervalInputs in;
        in.stages[0] = unormTile(0, 1);
        in.stages[1].value.fill(ValueRange::point(0));
        IntervalResult r = evaluateOnce(shader, prec, {}, in);
        CHECK(r.copyStage == 0);
        CHECK(r.copyInstruction == 0);  // tex t0
        CHECK_FALSE(r.constantColor());
        // A zero of unknown sign keeps the copy: t0 is never −0.0, and t0 + (±0) = t0.
        in.stages[1].value.fill(ValueRange::between(0, 0));
        CHECK(evaluateOnce(shader, prec, {}, in).copyStage == 0);
        // A scene that may hold −0.0 (a float texture): −0 + +0 = +0 in float, so no copy there.
        in.stages[0].value.fill(ValueRange::between(0, 1, true));
        in.stages[1].value.fill(ValueRange::point(0));
        CHECK(evaluateOnce(shader, prec, {}, in).copyStage == (isFixedPoint(prec) ? 0 : -1));
        // Texels past MaxValue are clamped when loaded (not in ideal): no copy of the texel.
        in.stages[0] = unormTile(0, 4);
        CHECK(evaluateOnce(shader, prec, {}, in).copyStage == (prec == Precision::Ideal ? 0 : -1));
        // Both tiles zero: the constant 0.
        in.stages[0] = unormTile(0, 0);
        in.stages[1] = unormTile(0, 0);
        requireConstant(evaluateOnce(shader, prec, {}, in), {0, 0, 0, 0}, prec);
        // Glare present: neither.
        in.stages[0] = unormTile(0, 1);
        in.stages[1] = unormTile(0, 0.1);
        r = evaluateOnce(shader, prec, {}, in);
        CHECK(r.copyStage == -1);
        CHECK_FALSE(r.color[0].constant);
        CHECK(r.color[0].hi == Approx(isFixedPoint(prec) || prec == Precision::Float ? 1.0 : 1.1).margin(1e-6));
    }
}

TEST_CASE("intervals: the screen and luminance composites over a zero glare tile are copies too", "[intervals]") {
    for (Precision prec : kProfiles) {
        INFO(precisionName(prec));
        IntervalInputs in;
        in.stages[0] = unormTile(0, 1);
        in.stages[1] = unormTile(0, 0);
        // S + G − S·G as mad: G·(1 − S) + S, the product exactly 0.
        CHECK(evaluateOnce(glareShader("composite_screen.psh"), prec, {}, in).copyStage == 0);
        // lrp(lum, S, S + G) with S + G a copy of S: f·S + (1 − f)·S is S.
        const IntervalResult r = evaluateOnce(glareShader("composite_luminance.psh"), prec, {}, in);
        CHECK(r.copyStage == 0);
        CHECK(r.copyInstruction == 1);  // def c0, then tex t0
    }
}

TEST_CASE("intervals: a screen composite over a zero glare whose alpha is one copies the scene's r g b", "[intervals]") {
    // The blurred glare of a bright pass keeps alpha 1: S + G·(1 − S) then has r g b = S, and
    // alpha 1·(1 − Sa) + Sa, which is 1 over a scene alpha of 0. Over an unknown one the fx
    // profiles still give exactly 1 (the numerator 2G·(2G − 2n) + 2G·2n is 4G² for every n, which
    // the mad's corners over the shared t0.a find); float's rounding is not proven.
    for (Precision prec : kProfiles) {
        INFO(precisionName(prec));
        IntervalInputs in;
        in.stages[0] = unormTile(0, 1);
        in.stages[0].value[3] = ValueRange::point(0);
        in.stages[1] = unormTile(0, 0);
        in.stages[1].value[3] = ValueRange::point(1);
        IntervalResult r = evaluateOnce(glareShader("composite_screen.psh"), prec, {}, in);
        CHECK(r.copyStage == -1);
        CHECK(r.copyMask == 0x7);
        CHECK(r.channelCopyStage == 0);
        CHECK(r.channelCopyInstruction == 0);  // tex t0
        CHECK(r.color[3].constant);
        CHECK(r.color[3].lo == 1.0);
        in.stages[0].value[3] = ValueRange::between(0, 1, false);
        r = evaluateOnce(glareShader("composite_screen.psh"), prec, {}, in);
        CHECK(r.copyMask == 0x7);
        if (isFixedPoint(prec)) {
            CHECK(r.color[3].constant);
            CHECK(r.color[3].lo == 1.0);
        } else {
            CHECK_FALSE(r.color[3].constant);
        }
    }
}

TEST_CASE("intervals: products and blurs of constant tiles are constants", "[intervals]") {
    Consts k{};
    k[0] = {0.5f, 0.25f, 1.0f, 0.75f};
    for (Precision prec : kProfiles) {
        IntervalInputs in;
        in.stages[0].value = {ValueRange::point(0.2), ValueRange::point(0.4), ValueRange::point(0.6),
                              ValueRange::point(1)};
        const IntervalResult r = evaluateOnce("ps_1_1\ntex t0\nmul r0, t0, c0\n", prec, k, in);
        INFO(precisionName(prec));
        CHECK(r.constantColor());
        CHECK(r.color[0].lo == Approx(0.1).margin(0.003));
        CHECK(r.color[3].lo == Approx(0.75).margin(0.003));
        // blur4.psh over four zero taps.
        IntervalInputs zero;
        for (int s = 0; s < 4; ++s) zero.stages[size_t(s)] = unormTile(0, 0);
        requireConstant(evaluateOnce(glareShader("blur4.psh"), prec, {}, zero), {0, 0, 0, 0}, prec);
        // And over taps in [0, 1]: the weights sum to (about) one, so [0, 1].
        for (int s = 0; s < 4; ++s) zero.stages[size_t(s)] = unormTile(0, 1);
        const IntervalResult b = evaluateOnce(glareShader("blur4.psh"), prec, {}, zero);
        CHECK(b.color[0].lo == 0);
        CHECK(b.color[0].hi == Approx(1).margin(0.01));
    }
}

TEST_CASE("intervals: bounds are exact for the simple cases", "[intervals]") {
    Consts k{};
    k[0] = {0.5f, 0.5f, 0.5f, 0.5f};
    for (Precision prec : kProfiles) {
        INFO(precisionName(prec));
        IntervalInputs in;
        in.stages[0] = unormTile(51.0 / 255, 153.0 / 255);
        in.stages[1] = unormTile(0, 1);
        IntervalResult r = evaluateOnce("ps_1_1\ntex t0\nmov r0, t0\n", prec, k, in);
        CHECK(r.copyStage == 0);
        if (isFixedPoint(prec)) {
            const int32_t s = gridScale(prec) / 255;
            CHECK(r.color[0].gridLo == 51 * s);
            CHECK(r.color[0].gridHi == 153 * s);
        } else {
            CHECK(r.color[0].lo == double(float(51.0 / 255)));
            CHECK(r.color[0].hi == double(float(153.0 / 255)));
        }
        // lrp of independent sources stays inside the hull of its ends (not [-0.5, 1.5]).
        r = evaluateOnce("ps_1_1\ntex t0\ntex t1\nlrp r0, t0, t1, c0\n", prec, k, in);
        CHECK(r.color[0].lo >= -1e-5);
        CHECK(r.color[0].hi <= 1 + 1e-5);
        // Unknown inputs: the profile's whole range (fx), or unbounded (float, ideal).
        in.stages[0] = StageRange{};
        r = evaluateOnce("ps_1_1\ntex t0\nmov r0, t0\n", prec, k, in);
        CHECK(r.copyStage == -1);
        if (isFixedPoint(prec)) {
            CHECK(r.color[0].gridLo == -gridScale(prec));
            CHECK(r.color[0].gridHi == gridScale(prec));
        } else {
            CHECK_FALSE(r.color[0].bounded);
        }
        // _sat bounds anything, NaN included.
        r = evaluateOnce("ps_1_1\ntex t0\nmov_sat r0, t0\n", prec, k, in);
        CHECK(r.color[0].bounded);
        CHECK(r.color[0].lo == 0);
        CHECK(r.color[0].hi == 1);
    }
}

TEST_CASE("intervals: identities that keep a copy, conditions decided by their ranges", "[intervals]") {
    Consts k{};
    k[0] = {1, 1, 1, 1};
    k[1] = {0, 0, 0, 0};
    k[2] = {0.75f, 0.75f, 0.75f, 0.75f};
    for (Precision prec : kProfiles) {
        INFO(precisionName(prec));
        IntervalInputs in;
        in.stages[0] = unormTile(0, 1);
        in.stages[1] = unormTile(0, 0);
        in.stages[2] = unormTile(0.6, 1);
        CHECK(evaluateOnce("ps_1_1\ntex t0\nmul r0, t0, c0\n", prec, k, in).copyStage == 0);
        CHECK(evaluateOnce("ps_1_1\ntex t0\ntex t1\nmad r0, t1, c2, t0\n", prec, k, in).copyStage == 0);
        CHECK(evaluateOnce("ps_1_1\ntex t0\nmad r0, t0, c0, c1\n", prec, k, in).copyStage == 0);
        CHECK(evaluateOnce("ps_1_1\ntex t0\ntex t1\nlrp r0, c1, t1, t0\n", prec, k, in).copyStage == 0);
        CHECK(evaluateOnce("ps_1_1\ntex t0\ntex t1\nlrp r0, c0, t0, t1\n", prec, k, in).copyStage ==
              (isFixedPoint(prec) ? 0 : -1));  // b + 1·(a − b) rounds in float
        // cnd on r0.a > 0.5 everywhere in the tile: the first source.
        CHECK(evaluateOnce("ps_1_1\ntex t0\ntex t2\nmov r0, t2\ncnd r0, r0.a, t0, c1\n", prec, k, in).copyStage == 0);
        CHECK(evaluateOnce("ps_1_2\ntex t0\ntex t2\ncmp r0, t2, t0, c2\n", prec, k, in).copyStage == 0);
        // _sat keeps a [0, 1] copy; a shift does not.
        CHECK(evaluateOnce("ps_1_1\ntex t0\nmov_sat r0, t0\n", prec, k, in).copyStage == 0);
        CHECK(evaluateOnce("ps_1_1\ntex t0\nmov_x2 r0, t0\n", prec, k, in).copyStage == -1);
        // A swizzle is not a copy channel for channel.
        CHECK(evaluateOnce("ps_1_1\ntex t0\nmov r0, t0.a\n", prec, k, in).copyStage == -1);
        // ps_1_4: texld of a coordinate set is a plain lookup; of a register, a dependent one.
        CHECK(evaluateOnce("ps_1_4\ntexld r0, t0\n", prec, k, in).copyStage == 0);
        CHECK(
            evaluateOnce("ps_1_4\ntexld r1, t1\nadd r0, r1, c1\nphase\ntexld r0, t0\n", prec, k, in).copyInstruction ==
            3);
    }
}

TEST_CASE("intervals: dependent reads need a range for any coordinates; texkill and depth", "[intervals]") {
    for (Precision prec : kProfiles) {
        INFO(precisionName(prec));
        IntervalInputs in;
        in.stages[0] = unormTile(0, 1);
        in.stages[1] = unormTile(0, 0.5);
        const std::string bem = "ps_1_1\ntex t0\ntexbem t1, t0\nmov r0, t1\n";
        IntervalResult r = evaluateOnce(bem, prec, {}, in);
        CHECK(r.copyStage == -1);
        CHECK((isFixedPoint(prec) ? r.color[0].gridHi == gridScale(prec) : !r.color[0].bounded));
        in.stages[1].anyCoords = true;
        r = evaluateOnce(bem, prec, {}, in);
        CHECK(r.color[0].bounded);
        CHECK(r.color[0].hi == Approx(0.5).margin(0.003));
        CHECK(r.copyStage == -1);  // a dependent lookup is never a copy the renderer could make

        {
            Diagnostics diags;
            IntervalSetup setup;
            setup.options.precision = prec;
            auto e = IntervalEvaluator::create(mustAssemble(bem), setup, diags);
            REQUIRE(e);
            CHECK(e->plainLookupStages() == 1u);
            CHECK(e->dependentLookupStages() == 2u);
            CHECK(e->texcoordSetsRead() == 0);
            CHECK(e->colorsRead() == 0);
        }

        const std::string kill = "ps_1_1\ntex t0\ntexkill t1\nmov r0, t0\n";
        in.texcoord[1].fill(ValueRange::between(0, 1));
        CHECK(evaluateOnce(kill, prec, {}, in).kill == KillRange::Never);
        in.texcoord[1][2] = ValueRange::between(-1, 1);
        CHECK(evaluateOnce(kill, prec, {}, in).kill == KillRange::Maybe);
        in.texcoord[1][0] = ValueRange::between(-1, -0.5);
        CHECK(evaluateOnce(kill, prec, {}, in).kill == KillRange::Always);
        CHECK(evaluateOnce("ps_1_1\ntex t0\nmov r0, t0\n", prec, {}, in).kill == KillRange::Never);

        r = evaluateOnce("ps_1_3\ntex t0\ntexm3x2pad t1, t0\ntexm3x2depth t2, t0\nmov r0, t0\n", prec, {}, in);
        CHECK(r.writesDepth);
        CHECK(r.depth.lo >= 0);
        CHECK(r.depth.hi <= 1);
    }
}

TEST_CASE("texel tiles: each tile's facts are the exact ranges, NaN and -0 of its texels", "[intervals][tiles]") {
    std::mt19937_64 rng(0x7117e5);
    constexpr float kInf = std::numeric_limits<float>::infinity();
    const float specials[] = {0.0f, -0.0f, std::numeric_limits<float>::quiet_NaN(), kInf, -kInf, -3.5f, 1e30f, 0.25f};
    for (int iter = 0; iter < 60; ++iter) {
        const bool unorm8 = iter % 2 == 0;
        // (The last ones wider than 64 tiles of the largest side: scanned in groups of tiles.)
        const uint32_t w = iter >= 56 ? 2049 + uint32_t(rng() % 300) : 1 + uint32_t(rng() % (iter < 20 ? 40 : 300));
        const uint32_t h = iter >= 56 ? 1 + uint32_t(rng() % 70) : 1 + uint32_t(rng() % (iter < 20 ? 40 : 300));
        const int flavour = int(rng() % 3);  // 0: random, 1: mostly one value, 2: specials often
        std::vector<uint8_t> bytes;
        std::vector<float> floats;
        if (unorm8) {
            bytes.resize(size_t(w) * h * 4);
            const uint8_t base = uint8_t(rng());
            for (uint8_t& b : bytes) b = flavour == 1 && rng() % 64 ? base : uint8_t(rng());
        } else {
            floats.resize(size_t(w) * h * 4);
            for (float& f : floats)
                f = flavour == 1 && rng() % 64   ? 0.5f
                    : flavour == 2 && rng() % 4 == 0 ? specials[rng() % 8]
                                                     : float(std::ldexp(double(int64_t(rng() % 2001) - 1000), -8));
        }
        const std::optional<Texture> t = tiletest::levelTexture(unorm8, w, h, bytes, floats);
        TexelTiles tiles;
        prepareTexelTiles(*t, tiles);
        // In two halves, as workers scan them.
        scanTexelTiles(*t, tiles, 0, tiles.tilesY / 2);
        scanTexelTiles(*t, tiles, tiles.tilesY / 2, tiles.tilesY);
        for (uint32_t ty = 0; ty < tiles.tilesY; ++ty)
            for (uint32_t tx = 0; tx < tiles.tilesX; ++tx) {
                float lo[4] = {kInf, kInf, kInf, kInf}, hi[4] = {-kInf, -kInf, -kInf, -kInf};
                uint8_t nan = 0, negZero = 0;
                for (uint32_t y = ty * tiles.side; y < std::min(h, (ty + 1) * tiles.side); ++y)
                    for (uint32_t x = tx * tiles.side; x < std::min(w, (tx + 1) * tiles.side); ++x)
                        for (int c = 0; c < 4; ++c) {
                            const float f = t->texelValue(0, x, y)[size_t(c)];
                            if (std::isnan(f)) {
                                nan |= uint8_t(1 << c);
                                continue;
                            }
                            if (f == 0 && std::signbit(f)) negZero |= uint8_t(1 << c);
                            lo[c] = std::min(lo[c], f), hi[c] = std::max(hi[c], f);
                        }
                const TexelRange& r = tiles.tiles[size_t(ty) * tiles.tilesX + tx];
                INFO((unorm8 ? "A8R8G8B8 " : "A32B32G32R32F ") << w << "x" << h << " tile " << tx << "," << ty);
                CHECK(r.nan == nan);
                CHECK(r.negZero == negZero);
                for (int c = 0; c < 4; ++c) {
                    if (lo[c] > hi[c]) {  // only NaNs: the empty range
                        CHECK(r.lo[size_t(c)] > r.hi[size_t(c)]);
                        continue;
                    }
                    CHECK(r.lo[size_t(c)] == lo[c]);
                    CHECK(r.hi[size_t(c)] == hi[c]);
                }
            }
    }
}
