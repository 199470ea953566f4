// The fx8 fast path, driver: decides whether a program can run on int16 lanes, translates its
// arithmetic ops (modifier affine k = a·n + b, write-step clamps), and runs spans chunk by chunk.
// Texture instructions keep using the generic texture stage (executor_texture.cpp) on the int32
// bank: the registers they read and write are converted around them.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include "ps11/executor_fast.h"
#include "ps11/texture.h"

namespace ps11::exec {
namespace {

// Source modifier as k = a·n + b for G = 255 (sourceAffine, ps11/decoded_program.h); _dz/_dw have
// no arithmetic meaning and keep a program off the fast path.
bool fastAffine(SrcMod m, int16_t& a, int16_t& b) {
    if (m == SrcMod::Dz || m == SrcMod::Dw) return false;
    const SourceAffine af = sourceAffine(m, 255);
    a = int16_t(af.a), b = int16_t(af.b);
    return true;
}

bool fastKind(Opcode op, FastKind& k) {
    switch (op) {
        case Opcode::Mov:
            k = FastKind::Mov;
            return true;
        case Opcode::Add:
            k = FastKind::Add;
            return true;
        case Opcode::Sub:
            k = FastKind::Sub;
            return true;
        case Opcode::Mul:
            k = FastKind::Mul;
            return true;
        case Opcode::Mad:
            k = FastKind::Mad;
            return true;
        case Opcode::Dp3:
            k = FastKind::Dp3;
            return true;
        case Opcode::Dp4:
            k = FastKind::Dp4;
            return true;
        case Opcode::Lrp:
            k = FastKind::Lrp;
            return true;
        case Opcode::Cnd:
            k = FastKind::Cnd;
            return true;
        case Opcode::Cmp:
            k = FastKind::Cmp;
            return true;
        default:
            return false;  // bem (and anything new) stays on the generic path
    }
}

// Texture ops that write all four components of their destination for every lane, so the
// int32 copy of the destination need not be brought up to date first: every one that writes its
// destination (the opcode table's writesDst) writes it whole, save 1_4's texcrd (its mask only).
bool textureWritesAll(const DOp& op, int minor) {
    if (op.op == Opcode::TexCoord && minor >= 4) return false;
    return op.info->cls == OpClass::Texture && op.info->writesDst;
}

struct FastRunState {
    RunState st;
    FastBank bank;
    uint64_t constsId = 0;  // the constants the bank's c# slots hold (0: none)
};

// c0..c7 as lanes, unless this thread's bank already holds them (the same constsId).
void fillConstants(FastRunState& fs, const FastProgram& fp, const Profile& p, uint64_t constsId) {
    if (constsId != 0 && fs.constsId == constsId) return;
    for (int i = 0; i < kNumConsts; ++i)
        if ((fp.constsUsed >> i) & 1)
            for (int c = 0; c < 4; ++c)
                std::fill_n(fs.bank.reg[kFastConstSlot + i][c], kChunk, int16_t(p.constGrid[size_t(i)][size_t(c)]));
    fs.constsId = constsId;
}

void toInt32(const int16_t* s, int32_t* d, int n) {
    for (int i = 0; i < n; ++i) d[i] = s[i];
}

void syncTo32(FastRunState& fs, int slot) {
    for (int c = 0; c < 4; ++c) toInt32(fs.bank.reg[slot][c], fs.st.bi.reg[slot][c], fs.st.n);
}
// Texture results to int16, clamped to ±round(M·G) (tex/texld defer that clamp to here).
void syncTo16(FastRunState& fs, int slot, const FastKernels& k, int32_t nMax) {
    for (int c = 0; c < 4; ++c) k.narrow(fs.st.bi.reg[slot][c], fs.bank.reg[slot][c], fs.st.n, int16_t(nMax));
}

// One arithmetic op, and its copy out of tmp when it was computed there.
void arithStep(const FastKernels& kern, const FastOp& f, FastBank& bank, int nv) {
    kern.arith(f, bank, nv);
    if (f.viaTemp)
        for (int c = 0; c < 4; ++c)
            if ((f.mask >> c) & 1) std::memcpy(bank.reg[f.dst][c], bank.tmp[c], sizeof(int16_t) * size_t(nv));
}

// After op idx: if it ends a co-issued pair, both members have read; now the first writes (spec §3.5).
void commitPair(const std::vector<DOp>& ops, size_t idx, FastBank& bank, int nv) {
    if (ops[idx].hold || idx == 0 || !ops[idx - 1].hold) return;
    const DOp& first = ops[idx - 1];
    for (int c = 0; c < 4; ++c)
        if ((first.mask >> c) & 1)
            std::memcpy(bank.reg[first.dstSlot][c], bank.hold[c], sizeof(int16_t) * size_t(nv));
}

// The v# lanes [off, off + n) of a chunk, saturated and rounded once per pixel (docs/precision.md
// "Inputs"), as the generic path; a uniform channel (PixelInputs::uniformColor) converted once.
void loadColors(const FastKernels& kern, int32_t g, const PixelInputs& inputs, uint8_t vUsed, int off, int n,
                FastBank& bank) {
    for (int v = 0; v < kNumRegV; ++v) {
        if (!((vUsed >> v) & 1)) continue;
        for (int c = 0; c < 4; ++c) {
            const float* src = colorLanes(inputs, v, c, off);
            if (uniformColor(inputs, v, c))
                fillLanes(bank.reg[kSlotV + v][c], n, int16_t(colorGrid(src[0], g)));
            else
                kern.loadColor(src, bank.reg[kSlotV + v][c], n);
        }
    }
}

}  // namespace

const FastKernels* fastKernels(SimdLevel level) {
#if defined(PS11_HAVE_AVX512)
    return simdTable(level, &sse2::kKernels, &avx2::kKernels, &avx512::kKernels);
#elif defined(PS11_HAVE_AVX2)
    return simdTable(level, &sse2::kKernels, &avx2::kKernels);
#else
    (void)level;
    return nullptr;
#endif
}

bool buildFastProgram(const Profile& p, const std::vector<DOp>& ops, FastProgram& fp) {
    fp = FastProgram{};
    if (!fastKernels(SimdLevel::Baseline) || p.precision != Precision::Fx8 || p.g != 255 || p.nMax > kFastMaxGrid || p.nMax < 1) return false;
    fp.ops.resize(ops.size());
    fp.syncDstBefore.assign(ops.size(), 0);
    fp.r0Preset = r0PresetChannels(ops);
    for (size_t i = 0; i < ops.size(); ++i) {
        const DOp& d = ops[i];
        if (d.texture) fp.syncDstBefore[i] = !textureWritesAll(d, p.minor);
        if (d.texture || d.op == Opcode::Phase) continue;
        FastOp& f = fp.ops[i];
        if (!fastKind(d.op, f.kind)) return false;
        f.hold = d.hold;
        f.dst = d.dstSlot;
        f.mask = d.mask;
        f.shift = d.shift;
        if (d.shift < -3 || d.shift > 3) return false;
        // The write-step bounds exactly as executor_arith_fx.inc forms them.
        f.lo = int16_t(d.sat ? (p.nMax < 0 ? p.nMax : 0) : -p.nMax);
        f.hi = int16_t(d.sat ? (255 < p.nMax ? 255 : p.nMax) : p.nMax);
        f.numSrc = d.numSrc;
        for (int s = 0; s < 3; ++s) {
            FastSrc& fs = f.src[size_t(s)];
            if (s >= d.numSrc) {
                fs = FastSrc{};
                fs.slot = uint8_t(kFastConstSlot);  // never read by the op's formula; any valid lanes
                continue;
            }
            const DSrc& ds = d.src[size_t(s)];
            if (ds.kind == SrcKind::TexCoord) return false;
            fs.slot = uint8_t(ds.kind == SrcKind::Const ? kFastConstSlot + (ds.slot & 7) : ds.slot);
            if (ds.kind == SrcKind::Const) fp.constsUsed = uint8_t(fp.constsUsed | (1u << (ds.slot & 7)));
            fs.sw = ds.sw;
            if (!fastAffine(ds.mod, fs.a, fs.b)) return false;
        }
        // Sources with even a and b (every modifier but _bias) let products run on k/2.
        f.half = true;
        for (int s = 0; s < f.numSrc; ++s)
            if ((f.src[size_t(s)].a & 1) || (f.src[size_t(s)].b & 1)) f.half = false;
        // Every value within ±255 (MaxValue 1), sources unmodified or negated, no shift: the
        // products fit 16 bits (productSmall).
        if ((f.kind == FastKind::Mul || f.kind == FastKind::Mad) && f.shift == 0 && p.nMax <= 255) {
            f.small = true;
            for (int s = 0; s < f.numSrc; ++s)
                if ((f.src[size_t(s)].a != 2 && f.src[size_t(s)].a != -2) || f.src[size_t(s)].b != 0) f.small = false;
        }
        // Component c of the destination is written before component c' > c is read: a source
        // that is the destination itself and reads other components must see the old values.
        if (!f.hold && f.kind != FastKind::Dp3 && f.kind != FastKind::Dp4) {
            for (int s = 0; s < f.numSrc; ++s) {
                const uint8_t rm = componentsRead(*d.info, s, d.mask);  // channels source s reads
                const FastSrc& fs = f.src[size_t(s)];
                if (fs.slot != f.dst) continue;
                for (int c = 0; c < 4; ++c)
                    if (((rm >> c) & 1) && fs.sw[size_t(c)] != c) f.viaTemp = true;
            }
        }
    }
    fp.ready = true;
    return true;
}

void runFast(const FastProgram& fp, const Profile& p, uint64_t constsId, const std::vector<DOp>& ops, uint8_t vUsed,
             bool writesDepth, const PixelInputs& inputs, Sampler& sampler, PixelOutputs& outputs) {
    const int count = std::clamp(inputs.count, 0, kMaxSpan);
    const ThreadCached<FastRunState> fs;  // no 60 KB allocation per span
    RunState& st = fs->st;
    FastBank& bank = fs->bank;
    st.in = &inputs;
    st.sampler = &sampler;
    // r0 is the output: its channels read before written, or never written, are 0 as in the
    // generic path. Lanes past a chunk's count (up to the next multiple of the kernels' lanes) are computed too
    // and never stored; the kernels use only wrapping SIMD arithmetic, so whatever those lanes
    // hold is harmless.
    for (int c = 0; c < 4; ++c)
        if ((fp.r0Preset >> c) & 1) std::memset(bank.reg[kSlotR][c], 0, sizeof bank.reg[kSlotR][c]);
    fillConstants(*fs, fp, p, constsId);
    const FastKernels& kern = *fastKernels(simdLevel());
    for (int off = 0; off < count; off += kChunk) {
        st.offset = off;
        st.n = std::min(kChunk, count - off);
        st.depthWritten = false;
        const int n = st.n;
        const int nv = (n + kern.lanes - 1) / kern.lanes * kern.lanes;
        std::memset(st.killed, 0, sizeof st.killed);
        loadColors(kern, p.g, inputs, vUsed, off, n, bank);
        for (size_t idx = 0; idx < ops.size(); ++idx) {
            const DOp& op = ops[idx];
            if (op.op == Opcode::Phase) continue;
            if (op.texture) {
                for (int s = 0; s < op.numSrc; ++s)
                    if (op.src[size_t(s)].kind == SrcKind::Reg) syncTo32(*fs, op.src[size_t(s)].slot);
                if (fp.syncDstBefore[idx]) syncTo32(*fs, op.dstSlot);  // texdepth reads it; texcrd keeps the rest
                st.deferTexelClamp = op.op == Opcode::Tex;
                execTexture(p, op, st);
                st.deferTexelClamp = false;
                if (op.info->writesDst) syncTo16(*fs, op.dstSlot, kern, p.nMax);
            } else {
                arithStep(kern, fp.ops[idx], bank, nv);
            }
            commitPair(ops, idx, bank, nv);
        }
        for (int c = 0; c < 4; ++c)
            kern.store(bank.reg[kSlotR][c], outputs.color[c] ? outputs.color[c] + off : nullptr,
                       outputs.grid[c] ? outputs.grid[c] + off : nullptr, n);
        if (outputs.killed) std::memcpy(outputs.killed + off, st.killed, size_t(n));
        if (outputs.depth && writesDepth && st.depthWritten)
            std::memcpy(outputs.depth + off, st.depth, sizeof(float) * size_t(n));
    }
}

// Chains of products run as one (FastKernels::chain): a small non-negative mul into R, followed
// by small non-negative mads of the same channels whose third source is R as it stands (plain,
// unswizzled) and whose factors never read R, all arithmetic ops next to each other (the
// weighted sums of the blurs: mul r0, t0, c0; mad r0, t1, c1, r0; ...). Only in programs without
// co-issued pairs (presampledOps' sign analysis).
static void markChains(const std::vector<DOp>& ops, std::vector<FastOp>& out) {
    auto product = [&](size_t i, FastKind kind) {
        const FastOp& f = out[i];
        return !ops[i].texture && ops[i].op != Opcode::Phase && f.kind == kind && f.small && f.nonNegative &&
               f.complement == 0 && !f.hold;
    };
    for (size_t head = 0; head < ops.size(); ++head) {
        if (!product(head, FastKind::Mul)) continue;
        const FastOp& h = out[head];
        if (h.src[0].slot == h.dst || h.src[1].slot == h.dst) continue;
        size_t end = head + 1;
        while (end < ops.size() && end - head < size_t(kMaxFastChain) && product(end, FastKind::Mad)) {
            const FastOp& m = out[end];
            const FastSrc& r = m.src[2];
            const bool addsR = r.slot == h.dst && r.a == 2 && r.b == 0 && r.sw == std::array<uint8_t, 4>{0, 1, 2, 3};
            if (!addsR || m.dst != h.dst || m.mask != h.mask || m.src[0].slot == h.dst || m.src[1].slot == h.dst)
                break;
            ++end;
        }
        if (end - head < 2) continue;
        out[head].chain = uint8_t(end - head);
        for (size_t k = head + 1; k < end; ++k) out[k].inChain = true;
        head = end - 1;
    }
}

void presampledOps(const FastProgram& fp, const Profile& p, const std::vector<DOp>& ops, std::vector<FastOp>& out,
                   bool plainTexels) {
    out = fp.ops;
    if (!fp.ready) return;
    // Sign analysis for productSmall: channels known >= 0 per slot (bit c). Taps are 8-bit texels
    // (>= 0), v# are in [0, 1], constants as they are; a mov or small mul/mad of known
    // non-negative sources with positive modifiers, or a _sat result, is >= 0. Programs with
    // co-issued pairs (results written late) skip the analysis.
    bool paired = false;
    for (const DOp& op : ops) paired = paired || op.hold;
    if (!paired) {
        std::array<uint8_t, kFastSlots> pos{};
        for (int v = 0; v < kNumRegV; ++v) pos[size_t(kSlotV + v)] = kMaskAll;
        for (int i = 0; i < kNumConsts; ++i)
            for (int c = 0; c < 4; ++c)
                if (p.constGrid[size_t(i)][size_t(c)] >= 0) pos[size_t(kFastConstSlot + i)] |= uint8_t(1u << c);
        auto known = [&](const FastSrc& s, int c) { return (pos[s.slot] >> s.sw[size_t(c)]) & 1; };
        for (size_t idx = 0; idx < ops.size(); ++idx) {
            const DOp& op = ops[idx];
            if (op.op == Opcode::Phase || op.op == Opcode::TexKill) continue;  // (texkill writes nothing)
            if (op.texture) {
                pos[op.dstSlot] = op.plainRead && plainTexels ? kMaskAll : 0;
                continue;
            }
            FastOp& f = out[idx];
            uint8_t result = 0;
            // A factor 1 − n with n known in [0, 255] is 255 − n, also in [0, 255]: the 16-bit
            // kernel takes it (Sousa's screen composite, mad r0, t1, 1-t0, t0).
            if (!f.small && (f.kind == FastKind::Mul || f.kind == FastKind::Mad) && f.shift == 0 && p.nMax <= 255) {
                auto plain = [](const FastSrc& s) { return s.a == 2 && s.b == 0; };
                auto comp = [](const FastSrc& s) { return s.a == -2 && s.b == 510; };
                bool ok = f.kind == FastKind::Mul || ((f.src[2].a == 2 || f.src[2].a == -2) && f.src[2].b == 0);
                uint8_t compMask = 0;
                for (int s = 0; s < 2 && ok; ++s) {
                    const FastSrc& src = f.src[size_t(s)];
                    ok = plain(src) || comp(src);
                    for (int c = 0; c < 4 && ok; ++c)
                        if ((f.mask >> c) & 1) ok = known(src, c);
                    if (comp(src)) compMask = uint8_t(compMask | (1u << s));
                }
                if (ok && compMask) {
                    f.small = true;
                    f.nonNegative = true;
                    f.complement = compMask;
                    for (int c = 0; c < 4; ++c)
                        if ((f.mask >> c) & 1 && (f.kind == FastKind::Mul || (f.src[2].a > 0 && known(f.src[2], c))))
                            result |= uint8_t(1u << c);
                }
            } else if (f.small && f.src[0].a > 0 && f.src[1].a > 0) {
                bool all = true;
                for (int c = 0; c < 4; ++c)
                    if ((f.mask >> c) & 1) all = all && known(f.src[0], c) && known(f.src[1], c);
                f.nonNegative = all;
                if (all)
                    for (int c = 0; c < 4; ++c)
                        if ((f.mask >> c) & 1 && (f.kind == FastKind::Mul || (f.src[2].a > 0 && known(f.src[2], c))))
                            result |= uint8_t(1u << c);
            } else if (f.kind == FastKind::Mov && f.src[0].a > 0 && f.src[0].b == 0) {
                for (int c = 0; c < 4; ++c)
                    if (known(f.src[0], c)) result |= uint8_t(1u << c);
            }
            // Every written channel's result >= 0 >= lo: the lower clamp is a no-op.
            f.lean = f.nonNegative && (result & f.mask) == f.mask && f.lo <= 0;
            if (f.lo >= 0) result = kMaskAll;
            pos[f.dst] = uint8_t((pos[f.dst] & ~f.mask) | (result & f.mask));
        }
        markChains(ops, out);
    }
}

void chainRowPlan(const FastProgram& fp, const Profile& p, const std::vector<DOp>& ops,
                  const std::vector<FastOp>& ops2, uint8_t vUsed, ChainRowPlan& out) {
    out = ChainRowPlan{};
    if (!fp.ready || vUsed != 0 || p.nMax < 255 || !fastKernels(simdLevel())) return;
    std::array<int8_t, kFastSlots> tapOf;  // the tap whose register a slot is (−1: none)
    tapOf.fill(-1);
    int taps = 0, head = -1;
    for (size_t i = 0; i < ops.size(); ++i) {
        const DOp& d = ops[i];
        if (d.op == Opcode::Phase) continue;
        if (d.op == Opcode::TexKill) return;  // (chain rows store every pixel)
        if (d.texture && !d.plainRead) return;  // (a chain row's taps are rows of texels)
        if (d.texture) {
            if (head >= 0) return;  // a read after the arithmetic began
            tapOf[d.dstSlot] = int8_t(taps++);
            continue;
        }
        if (head >= 0) {
            if (!ops2[i].inChain) return;  // arithmetic outside the chain
            continue;
        }
        head = int(i);
    }
    if (head < 0 || taps > 8) return;
    const FastOp& first = ops2[size_t(head)];
    // A chain, or one small non-negative product on its own.
    const bool single = first.chain == 0;
    if (single && !(first.small && first.nonNegative && (first.kind == FastKind::Mul || first.kind == FastKind::Mad)))
        return;
    if (first.dst != kSlotR || first.mask != kMaskAll) return;
    const std::array<uint8_t, 4> identity{0, 1, 2, 3};
    auto code = [&](const FastSrc& src, int8_t& c) {
        if (src.sw != identity) return false;
        if (src.slot >= kFastConstSlot) {
            c = int8_t(-1 - (src.slot - kFastConstSlot));
            return true;
        }
        c = tapOf[src.slot];
        return c >= 0;
    };
    const int count = single ? 1 : first.chain;
    for (int k = 0; k < count; ++k) {
        const FastOp& f = ops2[size_t(head + k)];
        if (f.lo > 0 || f.hi < 0) return;  // (no modifier clamps so: the kernels leave out the lower clamp)
        int8_t c0 = 0, c1 = 0;
        if (!code(f.src[0], c0) || !code(f.src[1], c1)) return;
        uint8_t comp = f.complement & 3;
        if (c0 < 0) {  // the tap first
            std::swap(c0, c1);
            comp = uint8_t(((comp & 1) << 1) | (comp >> 1));
        }
        if (c0 < 0 || (c1 < 0 && (comp & 2))) return;  // no tap, or a complemented constant
        out.factor[size_t(k)] = {c0, c1};
        out.complement[size_t(k)] = comp;
        if (comp & 1) out.flat = uint8_t(out.flat | (1u << c0));
        if (c1 >= 0) out.flat = uint8_t(out.flat | (1u << c1));
    }
    for (int i = 0; i < kNumConsts; ++i)
        for (int c = 0; c < 4; ++c)
            out.pattern[size_t(i)][size_t(kUnorm8Byte[c])] = int16_t(p.constGrid[size_t(i)][size_t(c)]);
    if (single && first.kind == FastKind::Mad) {
        // The addend as it is: unnegated, and >= 0 (the sum of non-negative terms then needs no
        // lower clamp beyond the op's own).
        const FastSrc& add = first.src[2];
        int8_t c = 0;
        if (add.a != 2 || add.b != 0 || !code(add, c)) return;
        if (c < 0)
            for (int16_t v : out.pattern[size_t(-1 - c)])
                if (v < 0) return;
        if (c >= 0) out.flat = uint8_t(out.flat | (1u << c));
        out.addend = c;
    }
    out.head = head;
    out.count = count;
    out.taps = taps;
    out.ready = true;
}

void runChainRow(const ChainRowPlan& plan, const std::vector<FastOp>& ops2, const ChainRowTap* taps, int count,
                 uint8_t* out, const ChainRowStore& store) {
    const FastKernels& kern = *fastKernels(simdLevel());
    const int bytes = 4 * std::clamp(count, 0, kMaxSpan);
    const int whole = bytes / kern.lanes * kern.lanes;
    const FastOp* ops = &ops2[size_t(plan.head)];
    // Halfway taps read other than as a first factor: their rows formed first (round_half_even of
    // each texel and the next one's sum).
    std::array<ChainRowTap, 8> own{};
    for (int t = 0; t < plan.taps && t < 8; ++t) own[size_t(t)] = taps[t];
    thread_local std::vector<uint8_t> formed;
    for (int t = 0; t < plan.taps && t < 8; ++t) {
        if (!((plan.flat >> t) & 1) || !taps[t].halfX) continue;
        formed.resize(size_t(8) * 4 * kMaxSpan);
        uint8_t* row = formed.data() + size_t(t) * 4 * kMaxSpan;
        halfwayBytes(taps[t].row, bytes, row);
        own[size_t(t)] = ChainRowTap{row, false};
    }
    if (whole) kern.chainRow(ops, plan, own.data(), whole, out, store.orMask, store.additive);
    if (whole == bytes) return;
    // The last lanes from copies of the texels they read, padded to a whole step.
    constexpr int kMaxLanes = 32;
    alignas(64) uint8_t texels[8][kMaxLanes + 4] = {};
    alignas(64) uint8_t last[kMaxLanes] = {};
    std::array<ChainRowTap, 8> rest{};
    const int n = bytes - whole;
    for (int t = 0; t < plan.taps && t < 8; ++t) {
        std::memcpy(texels[t], own[size_t(t)].row + whole, size_t(n + (own[size_t(t)].halfX ? 4 : 0)));
        rest[size_t(t)] = ChainRowTap{texels[t], own[size_t(t)].halfX};
    }
    if (store.additive) std::memcpy(last, out + whole, size_t(n));
    kern.chainRow(ops, plan, rest.data(), kern.lanes, last, store.orMask, store.additive);
    std::memcpy(out + whole, last, size_t(n));
}

// Texel lanes clamped to ±m. Out of line: inlined, its hoisted broadcast of m (a 16-bit store
// read back as 32 bits, which the store buffer cannot forward) stalled every call.
[[gnu::noinline]] static void clampLanes(int16_t* const dst[4], int n, int16_t m) {
    const int16_t lo = int16_t(-m);
    for (int c = 0; c < 4; ++c)
        for (int i = 0; i < n; ++i) dst[c][i] = std::min<int16_t>(std::max<int16_t>(dst[c][i], lo), m);
}

void runFastPresampled(const FastProgram& fp, const Profile& p, uint64_t constsId, const std::vector<DOp>& ops,
                       const std::vector<FastOp>& ops2, uint8_t vUsed, bool writesDepth, const PixelInputs& inputs,
                       TapFill fill, ResultSink sink, void* ctx, const PresampledRun& run) {
    const PixelOutputs* outputs = run.outputs;
    const int count = std::clamp(inputs.count, 0, kMaxSpan);
    const ThreadCached<FastRunState> fs;  // no 60 KB allocation per span
    FastBank& bank = fs->bank;
    RunState& st = fs->st;  // (the texture instructions run() would sample)
    st.in = &inputs;
    st.sampler = run.sampler;
    // r0's channels read before written, or never written, are 0 (as in runFast).
    for (int c = 0; c < 4; ++c)
        if ((fp.r0Preset >> c) & 1) std::memset(bank.reg[kSlotR][c], 0, sizeof bank.reg[kSlotR][c]);
    fillConstants(*fs, fp, p, constsId);
    const FastKernels& kern = *fastKernels(simdLevel());
    const int16_t m = int16_t(p.nMax);
    for (int off = 0; off < count; off += kChunk) {
        const int n = std::min(kChunk, count - off);
        const int nv = (n + kern.lanes - 1) / kern.lanes * kern.lanes;
        st.offset = off;
        st.n = n;
        st.depthWritten = false;
        std::memset(st.killed, 0, sizeof st.killed);
        loadColors(kern, p.g, inputs, vUsed, off, n, bank);
        int tap = 0;
        for (size_t idx = 0; idx < ops.size(); ++idx) {
            const DOp& op = ops[idx];
            if (op.op == Opcode::Phase) continue;
            // (The caller tests TapPlan::killSets; a register's texkill runs below.)
            if (op.op == Opcode::TexKill && op.src[0].kind == SrcKind::TexCoord) continue;
            // (A plain read the caller leaves to the executor is sampled as the others are.)
            if (op.texture && (!op.plainRead || ((run.executedTaps >> tap) & 1))) {
                tap += op.plainRead;
                // As runFast runs it: its registers through the int32 bank.
                for (int s = 0; s < op.numSrc; ++s)
                    if (op.src[size_t(s)].kind == SrcKind::Reg) syncTo32(*fs, op.src[size_t(s)].slot);
                if (fp.syncDstBefore[idx]) syncTo32(*fs, op.dstSlot);
                st.deferTexelClamp = op.op == Opcode::Tex;
                execTexture(p, op, st);
                st.deferTexelClamp = false;
                if (op.info->writesDst) syncTo16(*fs, op.dstSlot, kern, p.nMax);
            } else if (op.texture) {
                // A plain read (tapPlan): the caller's texels, clamped to ±M as sampleInto does
                // (a no-op for 8-bit texels when M >= 1).
                int16_t* const dst[4] = {bank.reg[op.dstSlot][0], bank.reg[op.dstSlot][1], bank.reg[op.dstSlot][2],
                                         bank.reg[op.dstSlot][3]};
                fill(ctx, tap, off, n, dst);
                if (m < 255) clampLanes(dst, n, m);
                ++tap;
            } else if (ops2[idx].chain) {
                kern.chain(&ops2[idx], ops2[idx].chain, bank, nv);
            } else if (!ops2[idx].inChain) {
                arithStep(kern, ops2[idx], bank, nv);
            }
            commitPair(ops, idx, bank, nv);
        }
        const int16_t* const r0[4] = {bank.reg[kSlotR][0], bank.reg[kSlotR][1], bank.reg[kSlotR][2],
                                      bank.reg[kSlotR][3]};
        sink(ctx, off, n, r0);
        if (outputs && outputs->killed) std::memcpy(outputs->killed + off, st.killed, size_t(n));
        if (outputs && outputs->depth && writesDepth && st.depthWritten)
            std::memcpy(outputs->depth + off, st.depth, sizeof(float) * size_t(n));
    }
}

}  // namespace ps11::exec
