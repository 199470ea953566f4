// The range proof (ps11/range_proof.h): traces the interval evaluator on the class's profile for
// the per-instruction ranges and findings, bisects each input's range for where a clamp begins,
// and propagates a bound on |fx − float| through the op list (docs/intervals.md "The range proof").
#include "ps11/range_proof.h"

#include <algorithm>
#include <cmath>

#include "ps11/decoded_program.h"
#include "ps11/disassembler.h"
#include "ps11/opcodes.h"
#include "ps11/precision.h"

namespace ps11 {

RangeProofSetup::RangeProofSetup() {
    textures.fill(ValueRange::between(0, 1, false));
    filtered.fill(true);
    colors.fill(ValueRange::between(0, 1, false));
    texcoords.fill(ValueRange::between(0, 1, false));
}

double LevelBound::max() const {
    double m = 0;
    for (double v : levels) m = std::max(m, v);
    return bounded ? m : INFINITY;
}

const InstructionRange* RangeProof::firstClamp() const {
    for (const InstructionRange& r : instructions)
        if (r.step.clamps) return &r;
    return nullptr;
}

namespace {

using exec::DOp;
using exec::DSrc;
using exec::SrcKind;

// One input of the proof, for the onsets: a stage's texels, a colour or a coordinate set.
struct InputRef {
    enum Kind { Texture, Color, TexCoord } kind;
    int index;
    std::string name() const {
        return (kind == Texture ? "t" : kind == Color ? "v" : "tc") + std::to_string(index);
    }
};

IntervalInputs inputsOf(const RangeProofSetup& s, const InputRef* over = nullptr, ValueRange overRange = {}) {
    IntervalInputs in;
    for (int t = 0; t < kMaxTextureStages; ++t) {
        const ValueRange r = over && over->kind == InputRef::Texture && over->index == t ? overRange : s.textures[size_t(t)];
        in.stages[size_t(t)].value.fill(r);
        in.stages[size_t(t)].anyCoords = true;  // the range bounds every lookup of the stage
    }
    for (int v = 0; v < 2; ++v)
        in.color[size_t(v)].fill(over && over->kind == InputRef::Color && over->index == v ? overRange
                                                                                            : s.colors[size_t(v)]);
    for (int t = 0; t < kMaxTexCoordSets; ++t)
        in.texcoord[size_t(t)].fill(over && over->kind == InputRef::TexCoord && over->index == t
                                        ? overRange
                                        : s.texcoords[size_t(t)]);
    return in;
}

ValueRange rangeOf(const RangeProofSetup& s, const InputRef& r) {
    return r.kind == InputRef::Texture ? s.textures[size_t(r.index)]
           : r.kind == InputRef::Color ? s.colors[size_t(r.index)]
                                       : s.texcoords[size_t(r.index)];
}

// Whether the step of Program instruction `instruction` clamps with `in`.
bool clampsWith(const IntervalEvaluator& e, const IntervalInputs& in, int instruction) {
    IntervalResult r;
    std::vector<InstructionInterval> steps;
    e.trace(in, r, steps);
    for (const InstructionInterval& s : steps)
        if (s.instruction == instruction) return s.clamps != 0;
    return false;
}

// Bisects input `ref` for where the clamp of `instruction` begins, from below and from above.
void findOnsets(const IntervalEvaluator& e, const RangeProofSetup& setup, const InputRef& ref, int instruction,
                std::vector<ClampOnset>& out) {
    const ValueRange full = rangeOf(setup, ref);
    if (!std::isfinite(full.lo) || !std::isfinite(full.hi) || full.lo >= full.hi) return;
    auto clamps = [&](double lo, double hi) {
        return clampsWith(e, inputsOf(setup, &ref, ValueRange::between(lo, hi, full.negZero)), instruction);
    };
    constexpr int kSteps = 40;
    // From above: the largest hi with [lo, hi] clamp-free.
    if (!clamps(full.lo, full.lo)) {
        double ok = full.lo, bad = full.hi;
        for (int i = 0; i < kSteps; ++i) {
            const double mid = 0.5 * (ok + bad);
            (clamps(full.lo, mid) ? bad : ok) = mid;
        }
        out.push_back({ref.name(), true, ok});
    }
    // From below: the smallest lo with [lo, hi] clamp-free.
    if (!clamps(full.hi, full.hi)) {
        double ok = full.hi, bad = full.lo;
        for (int i = 0; i < kSteps; ++i) {
            const double mid = 0.5 * (ok + bad);
            (clamps(mid, full.hi) ? bad : ok) = mid;
        }
        out.push_back({ref.name(), false, ok});
    }
}

// ---- the bound on |fx − float| ----

// A register channel in the bound's pass: the hull of what both profiles can hold, and the
// largest difference between the two.
struct EV {
    double lo = 0, hi = 0, e = 0;
};

double mag(double lo, double hi) { return std::max(std::fabs(lo), std::fabs(hi)); }
double mag(const EV& v) { return mag(v.lo, v.hi); }

// A source modifier on a value (the formulas of docs/precision.md), in double.
double modValue(SrcMod m, double x) {
    switch (m) {
        case SrcMod::Neg: return -x;
        case SrcMod::Bias: return x - 0.5;
        case SrcMod::BiasNeg: return 0.5 - x;
        case SrcMod::Sign: return 2 * x - 1;
        case SrcMod::SignNeg: return 1 - 2 * x;
        case SrcMod::Comp: return 1 - x;
        case SrcMod::X2: return 2 * x;
        case SrcMod::X2Neg: return -2 * x;
        default: return x;
    }
}
double modScale(SrcMod m) {
    return m == SrcMod::Sign || m == SrcMod::SignNeg || m == SrcMod::X2 || m == SrcMod::X2Neg ? 2 : 1;
}

// The hull of one channel over both profiles; infinite when either is unbounded.
EV hullOf(const ChannelInterval& a, const ChannelInterval& b) {
    if (!a.bounded || !b.bounded) return {-INFINITY, INFINITY, INFINITY};
    return {std::min(a.lo, b.lo), std::max(a.hi, b.hi), 0};
}

class BoundPass {
public:
    BoundPass(const IntervalEvaluator& fx, const IntervalEvaluator& fl, const RangeProofSetup& setup)
        : m_fx(fx), m_fl(fl), m_setup(setup), m_round(0.5 / fx.profile().g) {}

    LevelBound run() {
        const exec::Profile& p = m_fx.profile();
        const double m = p.maxValue;
        // Registers read only after a write: anything within ±M in both.
        for (auto& slot : m_reg)
            for (EV& v : slot) v = {-m, m, 2 * m};
        for (EV& v : m_reg[exec::kSlotR]) v = {0, 0, 0};
        // v#: saturated in both, rounded to the grid in fx.
        for (int v = 0; v < exec::kNumRegV; ++v)
            for (int c = 0; c < 4; ++c) {
                const ValueRange& r = m_setup.colors[size_t(v)];
                m_reg[exec::kSlotV + v][c] = {std::clamp(r.lo, 0.0, 1.0), std::clamp(r.hi, 0.0, 1.0), m_round};
            }
        const IntervalInputs in = inputsOf(m_setup);
        IntervalResult rx, rf;
        m_fx.trace(in, rx, m_sx);
        m_fl.trace(in, rf, m_sf);
        const std::vector<DOp>& ops = m_fx.ops();
        EV hold[4];
        for (size_t k = 0; k < m_sx.size() && k < m_sf.size(); ++k) {
            const InstructionInterval &sx = m_sx[k], &sf = m_sf[k];
            const DOp& op = ops[size_t(sx.op)];
            EV out[4];
            if (op.texture)
                texture(op, sx, sf, out);
            else
                arith(op, sx, sf, out);
            if (sx.writes) {
                EV* dst = op.hold ? hold : m_reg[op.dstSlot];
                for (int c = 0; c < 4; ++c)
                    if ((sx.mask >> c) & 1) dst[c] = out[c];
            }
            const bool pairEnds = !op.hold && sx.op > 0 && ops[size_t(sx.op - 1)].hold;
            if (pairEnds) {
                const DOp& first = ops[size_t(sx.op - 1)];
                for (int c = 0; c < 4; ++c)
                    if ((first.mask >> c) & 1) m_reg[first.dstSlot][c] = hold[c];
            }
        }
        LevelBound b;
        for (int c = 0; c < 4; ++c) {
            const double e = m_reg[exec::kSlotR][c].e;
            b.levels[size_t(c)] = e * 255.0;
            b.bounded = b.bounded && std::isfinite(e);
        }
        return b;
    }

private:
    // The float profile's own rounding: a few float32 operations on values of this magnitude.
    static double floatSlack(double magnitude) { return 0x1p-20 * std::max(1.0, magnitude); }

    // Caps e by the width of the two profiles' hull, both values lying inside it, plus the float
    // rounding of reading an fx result out as n/G.
    static EV capped(EV v) {
        if (std::isfinite(v.hi - v.lo)) v.e = std::min(v.e, v.hi - v.lo + floatSlack(mag(v)));
        return v;
    }

    void texture(const DOp& op, const InstructionInterval& sx, const InstructionInterval& sf, EV out[4]) {
        const bool plainTex =
            op.op == Opcode::Tex && (m_fx.profile().minor < 4 || op.src[0].kind == SrcKind::TexCoord);
        for (int c = 0; c < 4; ++c) {
            EV v = hullOf(sx.dst[size_t(c)], sf.dst[size_t(c)]);
            if (plainTex) {
                // The same texels in both; fx weighs with w = round(f·256)/256, float with f:
                // Σ|Δw| <= 2(|Δu| + |Δv|) <= 1/128 over the four weights, which sum to 1 in both,
                // so the filtered values differ by at most (hi − lo)/256; fx then rounds once.
                const ValueRange& r = m_setup.textures[op.stage];
                const double width = std::isfinite(r.hi - r.lo) ? r.hi - r.lo : INFINITY;
                v.e = (m_setup.filtered[op.stage] ? width / 256 : 0) + m_round + floatSlack(mag(v));
            } else if (op.op == Opcode::TexCoord) {
                v.e = m_round + floatSlack(mag(v));  // the same float coordinates, rounded in fx
            } else {
                v.e = INFINITY;  // dependent lookups, matrix products: the hull's width
            }
            out[c] = capped(v);
        }
    }

    EV fetch(const DSrc& s, int channel, bool& evenK) const {
        const exec::Profile &px = m_fx.profile(), &pf = m_fl.profile();
        const int comp = s.sw[size_t(channel)];
        evenK = evenK && exec::sourceAffine(s.mod, px.g).b % 2 == 0;
        EV v;
        if (s.kind == SrcKind::Const) {
            const double a = modValue(s.mod, double(px.constGrid[s.slot][size_t(comp)]) / px.g);
            const double b = modValue(s.mod, double(pf.constF[s.slot][size_t(comp)]));
            return {std::min(a, b), std::max(a, b), std::fabs(a - b)};
        }
        if (s.kind == SrcKind::TexCoord) {
            const ValueRange& r = m_setup.texcoords[s.slot & 7];
            v = {r.lo, r.hi, 0};
        } else {
            v = m_reg[s.slot][comp];
        }
        const double a = modValue(s.mod, v.lo), b = modValue(s.mod, v.hi);
        return {std::min(a, b), std::max(a, b), v.e * modScale(s.mod)};
    }

    void arith(const DOp& op, const InstructionInterval& sx, const InstructionInterval& sf, EV out[4]) {
        const double roundFx = m_round;
        auto product = [](const EV& a, const EV& b) { return mag(a) * b.e + mag(b) * a.e + a.e * b.e; };
        auto finish = [&](double pre, bool exact, double magnitude, int c) {
            EV v = hullOf(sx.dst[size_t(c)], sf.dst[size_t(c)]);
            v.e = pre * std::ldexp(1.0, op.shift) + (exact ? 0 : roundFx) + floatSlack(std::max(magnitude, mag(v)));
            return capped(v);
        };
        if (op.op == Opcode::Dp3 || op.op == Opcode::Dp4) {
            bool even = true;
            double e = 0, magnitude = 0;
            const uint8_t reads = componentsRead(*op.info, 0, op.mask);  // dp3 .rgb, dp4 .rgba
            for (int k = 0; k < 4; ++k) {
                if (!((reads >> k) & 1)) continue;
                const EV a = fetch(op.src[0], k, even), b = fetch(op.src[1], k, even);
                e += product(a, b);
                magnitude += mag(a) * mag(b);
            }
            for (int c = 0; c < 4; ++c)
                if ((op.mask >> c) & 1) out[c] = finish(e, false, magnitude, c);
            return;
        }
        for (int c = 0; c < 4; ++c) {
            if (!((op.mask >> c) & 1)) continue;
            bool even = true;
            EV s[3];
            for (int i = 0; i < op.numSrc; ++i) s[i] = fetch(op.src[size_t(i)], c, even);
            double e = INFINITY, magnitude = 0;
            bool linear = false;
            for (int i = 0; i < op.numSrc; ++i) magnitude = std::max(magnitude, mag(s[i]));
            switch (op.op) {
                case Opcode::Mov:
                    e = s[0].e, linear = true;
                    break;
                case Opcode::Add:
                case Opcode::Sub:
                    e = s[0].e + s[1].e, linear = true;
                    break;
                case Opcode::Mul:
                    e = product(s[0], s[1]);
                    break;
                case Opcode::Mad:
                    e = product(s[0], s[1]) + s[2].e;
                    magnitude = mag(s[0]) * mag(s[1]) + mag(s[2]);
                    break;
                case Opcode::Lrp: {
                    // b + f·(a − b): a change of f moves it by |a − b|, of a by |f|, of b by |1 − f|.
                    const EV &f = s[0], &a = s[1], &b = s[2];
                    const double diff = std::max(std::fabs(a.hi - b.lo), std::fabs(a.lo - b.hi));
                    e = diff * f.e + mag(f) * a.e + mag(1 - f.hi, 1 - f.lo) * b.e + f.e * (a.e + b.e);
                    break;
                }
                case Opcode::Cnd:
                case Opcode::Cmp: {
                    // Decided alike in both profiles when the hull of the condition lies on one
                    // side; otherwise either source may be taken in either profile.
                    const bool cnd = op.op == Opcode::Cnd;
                    const EV& x = s[0];
                    const bool allTrue = cnd ? x.lo > 0.5 : x.lo >= 0, allFalse = cnd ? x.hi <= 0.5 : x.hi < 0;
                    if (allTrue)
                        e = s[1].e;
                    else if (allFalse)
                        e = s[2].e;
                    else
                        e = std::max(s[1].e, s[2].e) + (std::max(s[1].hi, s[2].hi) - std::min(s[1].lo, s[2].lo));
                    linear = true;
                    break;
                }
                default:  // bem: the matrix is not part of the proof's setup
                    e = INFINITY;
                    break;
            }
            // The fx write is exact when the numerator is a whole multiple of the grid: a linear
            // op of sources with even k (no bias or _bx2 half grid) and no down-shift.
            out[c] = finish(e, linear && even && op.shift >= 0, magnitude, c);
        }
    }

    const IntervalEvaluator& m_fx;
    const IntervalEvaluator& m_fl;
    const RangeProofSetup& m_setup;
    double m_round;  // half a grid step of the fx profile
    EV m_reg[exec::kNumSlots][4];
    std::vector<InstructionInterval> m_sx, m_sf;
};

std::optional<IntervalEvaluator> evaluatorFor(const Program& program, const RangeProofSetup& setup, Precision precision,
                                              float maxValue, Diagnostics& diags) {
    IntervalSetup is;
    is.options = setup.options;
    is.options.precision = precision;
    is.options.maxValue = maxValue;
    is.constants = setup.constants;
    return IntervalEvaluator::create(program, is, diags);
}

}  // namespace

std::optional<RangeProof> proveRanges(const Program& program, const RangeProofSetup& setup, Diagnostics& diags) {
    std::optional<IntervalEvaluator> cls =
        evaluatorFor(program, setup, setup.options.precision, setup.options.maxValue, diags);
    if (!cls) return std::nullopt;
    RangeProof proof;
    proof.options = setup.options;
    const float m = cls->profile().maxValue;
    proof.options.maxValue = m;

    std::vector<InstructionInterval> steps;
    cls->trace(inputsOf(setup), proof.result, steps);
    std::vector<InputRef> inputs;
    const uint32_t stages = cls->plainLookupStages() | cls->dependentLookupStages();
    for (int t = 0; t < kMaxTextureStages; ++t)
        if ((stages >> t) & 1) inputs.push_back({InputRef::Texture, t});
    for (int v = 0; v < 2; ++v)
        if ((cls->colorsRead() >> v) & 1) inputs.push_back({InputRef::Color, v});
    for (int t = 0; t < kMaxTexCoordSets; ++t)
        if ((cls->texcoordSetsRead() >> t) & 1) inputs.push_back({InputRef::TexCoord, t});
    for (const InstructionInterval& s : steps) {
        InstructionRange r;
        r.step = s;
        const Instruction& inst = program.instructions[size_t(s.instruction)];
        r.loc = inst.loc;
        r.text = formatInstruction(inst, program.version);
        if (s.clamps)
            for (const InputRef& in : inputs) findOnsets(*cls, setup, in, s.instruction, r.onsets);
        proof.instructions.push_back(std::move(r));
    }

    // The bounds compare each fx profile with float at the class's MaxValue, capped to what the
    // fx profile holds (d3d9's 65504 in fx12). The program decoded once already: these cannot
    // fail for its sake, and their diagnostics would repeat the first's.
    for (Precision fxp : {Precision::Fx8, Precision::Fx12}) {
        LevelBound& out = fxp == Precision::Fx8 ? proof.fx8 : proof.fx12;
        const float mm = float(std::min(double(m), maxRepresentableValue(fxp)));
        Diagnostics quiet;
        std::optional<IntervalEvaluator> fl = evaluatorFor(program, setup, Precision::Float, mm, quiet);
        std::optional<IntervalEvaluator> fx = evaluatorFor(program, setup, fxp, mm, quiet);
        if (!fx || !fl) {
            out.bounded = false;
            out.levels.fill(INFINITY);
            continue;
        }
        out = BoundPass(*fx, *fl, setup).run();
    }
    return proof;
}

}  // namespace ps11
