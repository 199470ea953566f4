// The validator stage, operand and sequencing rules: register ranges and types, write masks,
// selectors, source and instruction modifiers, co-issue pairs, read ports, cnd/cmp/bem/texdepth,
// and the texm3x2/texm3x3 pad sequences (ps1x-spec.md §2.3, §2.4, §3, §4.3).
#include <algorithm>

#include "ps11/validator_internal.h"

namespace ps11::validator_detail {

// Register ranges and register types of the destination and the sources.
void Validator::checkRegisters(size_t i) {
    const Instruction& in = inst(i);
    const Opcode op = in.opcode();
    const int phase = m_phaseOf[i];
    if (in.info->hasDst) {
        const Dst& d = in.dst;
        if (!inRange(d.type, d.index))
            error(kRegRange, d.loc,
                  regName(d.type, d.index) + " is out of range: " + vname() + " has " + registerRange(d.type, m_minor));
        std::string allowed;
        bool ok = true;
        if (op == Opcode::Def) {
            ok = d.type == RegType::Const;
            allowed = "c#";
        } else if (isArith(in)) {
            ok = d.type == RegType::Temp || (!is14() && d.type == RegType::Texture);
            allowed = is14() ? "r# (ps_1_4 t# registers are read-only coordinates)" : "r# or t#";
        } else if (!is14()) {
            ok = d.type == RegType::Texture;
            allowed = "t#";
        } else if (op == Opcode::TexKill) {
            ok = d.type == RegType::Temp || d.type == RegType::Texture;
            allowed = "r# or t#";
        } else {
            ok = d.type == RegType::Temp;
            allowed = "r#";
        }
        if (!ok)
            error(kDstType, d.loc,
                  regName(d.type, d.index) + " cannot be the destination of " + mn(in) + " in " + vname() +
                      "; allowed: " + allowed);
    }
    for (size_t s = 0; s < in.info->numSrc; ++s) {
        const Src& src = in.src[s];
        if (!inRange(src.type, src.index))
            error(kRegRange, src.loc,
                  regName(src.type, src.index) + " is out of range: " + vname() + " has " +
                      registerRange(src.type, m_minor));
        const std::string name = regName(src.type, src.index);
        if (isArith(in)) {
            if (is14() && src.type == RegType::Texture)
                error(kTexRegIn14, src.loc,
                      name + " cannot be read by " + mn(in) +
                          ": in ps_1_4 t# registers are read only by texld, texcrd and texkill (use texcrd to copy "
                          "the coordinates into an r# first)");
            else if (is14() && src.type == RegType::Input && phase == 1)
                error(kInputInPhase1, src.loc, name + " is read in phase 1; ps_1_4 v# registers exist in phase 2 only");
        } else if (!is14()) {
            const bool eyeVector = op == Opcode::TexM3x3Spec && s == 1;
            const RegType want = eyeVector ? RegType::Const : RegType::Texture;
            if (src.type != want)
                error(kSrcType, src.loc,
                      name + " cannot be source " + std::to_string(s) + " of " + mn(in) +
                          (eyeVector ? ": the eye vector must be a constant c#"
                                     : ": texture-address instructions read t# registers only (c# only as the "
                                       "texm3x3spec eye vector)"));
        } else if (op == Opcode::Tex) {  // texld
            if (src.type == RegType::Temp && phase == 1)
                error(kDependentRead, src.loc,
                      "texld reads " + name + " in phase 1; an r# source (dependent read) is allowed in phase 2 only");
            else if (src.type != RegType::Temp && src.type != RegType::Texture)
                error(kSrcType, src.loc, name + " cannot be the source of texld; allowed: t# or (phase 2) r#");
        } else if (src.type != RegType::Texture) {  // texcrd
            error(kSrcType, src.loc, name + " cannot be the source of " + mn(in) + "; allowed: t#");
        }
    }
}

void Validator::checkMasks(size_t i) {
    const Instruction& in = inst(i);
    if (!in.info->hasDst) return;
    const Opcode op = in.opcode();
    const uint8_t mask = in.dst.mask & kMaskAll;
    if (op == Opcode::Def) {
        if (mask != kMaskAll)
            error(kDefOperand, in.dst.loc, "def writes a whole constant; found the write mask " + maskName(mask));
        if (in.dst.saturate || in.dst.shift != 0) error(kDefOperand, in.loc, "def takes no instruction modifier");
        return;
    }
    if (isArith(in)) {
        if (op == Opcode::Bem) {
            if (mask != (kMaskR | kMaskG))
                error(kTexMask14, in.dst.loc, "bem must write .rg exactly; found " + maskName(mask));
            return;
        }
        if (is14()) {
            if (mask == 0) error(kArithMask, in.dst.loc, "the write mask is empty");
            return;
        }
        if (op == Opcode::Dp3 && mask == kMaskA) {
            error(kDp3Mask, in.dst.loc,
                  "dp3 runs in the vector pipe; in " + vname() + " it may write .rgb or .rgba only, not .a");
            return;
        }
        if (mask != kMaskAll && mask != kMaskRGB && mask != kMaskA)
            error(kArithMask, in.dst.loc,
                  "write mask " + maskName(mask) + " is not allowed in " + vname() + "; allowed: .rgba, .rgb, .a");
        return;
    }
    // Texture instructions.
    if (!is14()) {
        if (mask != kMaskAll)
            error(kTexMask13, in.dst.loc,
                  mn(in) + " writes its whole register; " + vname() + " texture instructions take no write mask");
        return;
    }
    if (op == Opcode::TexCoord) {  // texcrd
        if (mask != kMaskAll && mask != kMaskRGB && mask != (kMaskR | kMaskG))
            error(kTexMask14, in.dst.loc, "texcrd may write .rgb, .rg or the whole register; found " + maskName(mask));
    } else if (mask != kMaskAll) {
        error(kTexMask14, in.dst.loc, mn(in) + " takes no write mask in ps_1_4; found " + maskName(mask));
    }
}

void Validator::checkSources(size_t i) {
    const Instruction& in = inst(i);
    const Opcode op = in.opcode();
    for (size_t s = 0; s < in.info->numSrc; ++s) {
        const Src& src = in.src[s];
        const std::string name = regName(src.type, src.index);
        if (isArith(in)) {
            // Modifiers.
            const bool x2 = src.mod == SrcMod::X2 || src.mod == SrcMod::X2Neg;
            const bool div = src.mod == SrcMod::Dz || src.mod == SrcMod::Dw;
            if (div)
                error(kSrcModVersion, src.loc,
                      srcModName(src.mod) + " is allowed only on texld/texcrd sources in ps_1_4, not on " + mn(in));
            else if (x2 && !is14())
                error(kSrcModVersion, src.loc, "the " + srcModName(src.mod) + " source modifier needs ps_1_4");
            if (src.type == RegType::Const && src.mod != SrcMod::None && !div && !(x2 && !is14())) {
                // Spec §3.1: undefined results in 1_1-1_3, a validation failure in 1_4.
                if (is14())
                    error(kConstModifier, src.loc,
                          "source modifier " + srcModName(src.mod) + " on constant " + name +
                              " fails validation in ps_1_4");
                else
                    m_diags.warning(kConstModifierWarn, src.loc,
                                    "source modifier " + srcModName(src.mod) + " on constant " + name +
                                        " gives undefined results in " + vname());
            }
            // Selectors.
            const uint8_t sw = src.swizzle;
            if (is14()) {
                bool ok = sw == tok::kIdentitySwizzle;
                for (int c = 0; c < 4; ++c) ok = ok || sw == replicateSwizzle(c);
                if (!ok)
                    error(kSelector, src.loc,
                          "source selector " + swizzleName(sw) +
                              " is not allowed in ps_1_4; allowed: none, .r, .g, .b, .a");
            } else if (sw == kSwBlue) {
                if ((in.dst.mask & kMaskAll) != kMaskA)
                    error(kBlueSelector, src.loc,
                          "the .b (blue replicate) selector is allowed in " + vname() +
                              " only when the instruction writes .a; the write mask is " + maskName(in.dst.mask));
            } else if (sw != tok::kIdentitySwizzle && sw != kSwAlpha) {
                error(kSelector, src.loc,
                      "source selector " + swizzleName(sw) + " is not allowed in " + vname() +
                          "; allowed: none, .a, and .b with an .a write mask");
            }
            continue;
        }
        if (!is14()) {
            // Texture-address sources (spec §2.3): no selector; only _bx2, and only on some instructions.
            if (src.swizzle != tok::kIdentitySwizzle)
                error(kTexSelector, src.loc,
                      mn(in) + " takes no source selector in " + vname() + "; found " + swizzleName(src.swizzle));
            if (src.mod == SrcMod::None) continue;
            const bool matrix = op == Opcode::TexM3x2Pad || op == Opcode::TexM3x3Pad || endsM3x2(op) || endsM3x3(op);
            const bool bx2Allowed =
                src.type == RegType::Texture && (m_minor == 1 ? matrix
                                                              : op != Opcode::TexReg2AR && op != Opcode::TexReg2GB &&
                                                                    op != Opcode::TexBem && op != Opcode::TexBemL);
            if (src.mod != SrcMod::Sign || !bx2Allowed)
                error(kTexSrcModifier, src.loc,
                      "source modifier " + srcModName(src.mod) + " is not allowed on the source of " + mn(in) + " in " +
                          vname() +
                          (m_minor == 1 ? " (only _bx2, on texm3x2*/texm3x3* sources)"
                                        : " (only _bx2, not on texreg2ar, texreg2gb, texbem, texbeml)"));
            continue;
        }
        // ps_1_4 texld / texcrd source forms (spec §2.4).
        if (src.mod != SrcMod::None && src.mod != SrcMod::Dz && src.mod != SrcMod::Dw) {
            error(kTexSrcModifier, src.loc,
                  "source modifier " + srcModName(src.mod) + " is not allowed on the source of " + mn(in) +
                      " (only _dz / _dw)");
            continue;
        }
        const uint8_t sw = src.swizzle;
        const bool texld = op == Opcode::Tex;
        std::string form;
        if (src.type == RegType::Texture) {
            if (src.mod == SrcMod::Dz)
                form = "_dz is allowed only on an r# source of texld; use t#_dw.xyw";
            else if (src.mod == SrcMod::Dw && sw != kSwXyw)
                form = "_dw needs the .xyw selector (" + name + "_dw.xyw)";
            else if (sw != tok::kIdentitySwizzle && sw != kSwXyz && sw != kSwXyw)
                form = "selector " + swizzleName(sw) + " is not allowed; use none, .xyz or .xyw";
        } else if (src.type == RegType::Temp && texld) {
            if (src.mod == SrcMod::Dw)
                form = "_dw is allowed only on a t# source; an r# source takes _dz";
            else if (sw != tok::kIdentitySwizzle && sw != kSwXyz)
                form = "selector " + swizzleName(sw) + " is not allowed on an r# source; use none or .xyz";
        }
        if (!form.empty()) error(kTexSourceForm, src.loc, "invalid " + mn(in) + " source form: " + form);
        if (src.mod == SrcMod::Dz && ++m_dzCount == 3)
            error(kTooManyDz, src.loc, "_dz may be used at most twice per shader; this is the third use");
        if (src.type == RegType::Texture && inRange(src.type, src.index) && form.empty()) {
            const int kind = sw == kSwXyw ? 2 : 1;
            int& seen = m_tSelector[src.index];
            if (seen == 0)
                seen = kind;
            else if (seen != kind)
                error(kMixedTexSelector, src.loc,
                      name + " is read with " + (kind == 2 ? ".xyw" : ".xyz") + " here but with " +
                          (seen == 2 ? ".xyw" : ".xyz") +
                          " earlier; every texld/texcrd read of a t# must use the same "
                          "selector");
        }
    }
}

void Validator::checkInstructionModifiers(size_t i) {
    const Instruction& in = inst(i);
    if (!in.info->hasDst || in.opcode() == Opcode::Def) return;
    const int shift = in.dst.shift;
    if (isTexture(in)) {
        // 1_1-1_3: none (spec §2.3, §3.2). 1_4 texld/texcrd: rejected too (our decision on open point §8.7).
        if (shift != 0 || in.dst.saturate)
            error(kTexInstModifier, in.loc,
                  mn(in) + " takes no instruction modifier; found " + (shift != 0 ? shiftName(shift) : std::string()) +
                      (in.dst.saturate ? "_sat" : ""));
        return;
    }
    if (shift == 0) return;
    if (shift < -3 || shift > 3)
        error(kShiftVersion, in.loc, "invalid shift scale " + std::to_string(shift));
    else if (!is14() && (shift == 3 || shift < -1))
        error(kShiftVersion, in.loc,
              "instruction modifier " + shiftName(shift) + " needs ps_1_4; " + vname() +
                  " allows _x2, _x4, _d2 and _sat");
}

void Validator::checkCoissue(size_t i) {
    const Instruction& in = inst(i);
    if (!in.coissue) return;
    if (!isArith(in) || !in.info->coissuable) {
        error(kNotCoissuable, in.loc,
              mn(in) + " cannot be co-issued (texture instructions, def, phase, nop, dp4 and bem never pair)");
        return;
    }
    if (i == 0 || !legal(i - 1) || !isArith(inst(i - 1)) || inst(i - 1).coissue) {
        std::string why = i == 0          ? "it is the first instruction"
                          : !legal(i - 1) ? "the previous instruction is invalid"
                          : inst(i - 1).coissue
                              ? "the previous instruction is already the second member of a pair"
                              : "the previous instruction (" + mn(inst(i - 1)) + ") is not an arithmetic instruction";
        error(kCoissuePlacement, in.loc, "'+' must follow a non-co-issued arithmetic instruction; " + why);
        return;
    }
    const Instruction& first = inst(i - 1);
    if (!first.info->coissuable) {
        error(kNotCoissuable, in.loc,
              mn(first) + " (" + lineRef(first.loc) + ") cannot be a member of a co-issued pair");
        return;
    }
    for (const Instruction* m : {&first, &in}) {
        if (m->opcode() == Opcode::Dp3 && (m->dst.mask & kMaskA)) {
            error(kCoissueDp3, m->loc,
                  "dp3 always runs in the vector pipe; in a pair it must write colour only, found " +
                      maskName(m->dst.mask));
            return;
        }
    }
    const Pipe a = pipeOf(first.dst.mask & kMaskAll), b = pipeOf(in.dst.mask & kMaskAll);
    const bool ok = (a == Pipe::Color && b == Pipe::Alpha) || (a == Pipe::Alpha && b == Pipe::Color);
    if (!ok)
        error(kCoissuePipes, in.loc,
              "a co-issued pair needs one colour instruction (" + std::string(is14() ? "rgb subset" : ".rgb") +
                  ") and one alpha instruction (.a); found " + maskName(first.dst.mask) + " and " +
                  maskName(in.dst.mask));
}

// Read ports: distinct registers of one type among the sources (spec §4.3), and over a pair (§3.5).
void Validator::checkReadPorts(size_t i) {
    const Instruction& in = inst(i);
    std::array<std::set<int>, 4> regs;
    for (size_t s = 0; s < in.info->numSrc; ++s) {
        const Src& src = in.src[s];
        if (size_t(src.type) >= regs.size()) continue;
        auto& set = regs[size_t(src.type)];
        if (!set.insert(src.index).second) continue;
        const int limit = m_limits.ports[size_t(src.type)];
        if (int(set.size()) == limit + 1)
            error(kReadPorts, src.loc,
                  vname() + " allows " + std::to_string(limit) + " different " + regPrefix(src.type) +
                      "# registers per instruction; " + regName(src.type, src.index) + " is number " +
                      std::to_string(limit + 1));
    }
    for (size_t t = 0; t < 4; ++t) m_stats.maxReadPorts[t] = std::max(m_stats.maxReadPorts[t], int(regs[t].size()));
    if (!pairsWithPrevious(i)) return;
    const Instruction& first = inst(i - 1);
    for (size_t s = 0; s < first.info->numSrc; ++s)
        if (size_t(first.src[s].type) < regs.size()) regs[size_t(first.src[s].type)].insert(first.src[s].index);
    for (size_t t = 0; t < 4; ++t) {
        const int n = int(regs[t].size());
        m_stats.maxPairReadPorts[t] = std::max(m_stats.maxPairReadPorts[t], n);
        if (n > m_stats.pairReadPortLimit) {
            std::string list;
            for (int r : regs[t]) list += (list.empty() ? "" : ", ") + regName(RegType(t), r);
            error(kPairReadPorts, in.loc,
                  "a co-issued pair may read at most " + std::to_string(m_stats.pairReadPortLimit) + " different " +
                      regPrefix(RegType(t)) + "# registers; this pair reads " + std::to_string(n) + " (" + list + ")");
        }
    }
}

// cnd, cmp, bem and texdepth rules.
void Validator::checkSpecial(size_t i) {
    const Instruction& in = inst(i);
    switch (in.opcode()) {
        case Opcode::Cnd: {
            const Src& s0 = in.src[0];
            if (!is14() &&
                !(s0.type == RegType::Temp && s0.index == 0 && s0.swizzle == kSwAlpha && s0.mod == SrcMod::None))
                error(kCndSrc0, s0.loc, "the condition of cnd must be exactly r0.a in " + vname());
            break;
        }
        case Opcode::Cmp:
            if (!is14()) {
                for (size_t s = 0; s < 3; ++s)
                    if (in.src[s].type == in.dst.type && in.src[s].index == in.dst.index) {
                        error(kCmpDstIsSrc, in.src[s].loc,
                              "cmp in " + vname() + ": the destination " + regName(in.dst.type, in.dst.index) +
                                  " must differ from every source register");
                        break;
                    }
            }
            break;
        case Opcode::Bem:
            if (m_phaseOf[i] != 1)
                error(kBemPhase, in.loc,
                      m_phaseInstruction < 0
                          ? "bem is allowed only in phase 1, and this shader has no phase instruction"
                          : "bem is allowed only in phase 1 (before the phase instruction)");
            break;
        case Opcode::TexDepth:
            if (!(in.dst.type == RegType::Temp && in.dst.index == 5))
                error(kTexDepthReg, in.dst.loc,
                      "texdepth works on r5 only; found " + regName(in.dst.type, in.dst.index));
            if (m_phaseOf[i] != 2) error(kTexDepthPhase, in.loc, "texdepth is allowed only in phase 2");
            break;
        default:
            break;
    }
}

// 1_1-1_3 texture destinations and sources: one texture instruction per t#, source index < destination index.
void Validator::checkTexRegisters(size_t i) {
    const Instruction& in = inst(i);
    if (is14() || !isTexture(in) || in.dst.type != RegType::Texture || !inRange(in.dst.type, in.dst.index)) return;
    const int m = in.dst.index;
    if (m_texDstSeen[m])
        error(kTexDstTwice, in.dst.loc,
              regName(RegType::Texture, m) + " is already the destination of a texture instruction at " +
                  lineRef(m_texDst[m]) + "; each t# (texture stage) takes one texture instruction");
    else
        m_texDstSeen[m] = true, m_texDst[m] = in.dst.loc;
    if (in.info->numSrc >= 1 && in.src[0].type == RegType::Texture && in.src[0].index >= m)
        error(kTexSrcIndex, in.src[0].loc,
              mn(in) + " " + regName(RegType::Texture, m) + " reads " + regName(RegType::Texture, in.src[0].index) +
                  "; the source register must have a smaller number than the destination");
}

// Pad sequences (spec §2.3): texm3x2pad t(m) + texm3x2tex/depth t(m+1); texm3x3pad t(m), t(m+1) + one of
// texm3x3tex/texm3x3/texm3x3spec/texm3x3vspec t(m+2); consecutive instructions, same source.
void Validator::checkTexSequences() {
    const size_t n = m_prog.instructions.size();
    auto opAt = [&](size_t j) { return j < n && inst(j).info ? inst(j).opcode() : Opcode::Comment; };
    auto checkRow = [&](const Instruction& pad, const Instruction& row, int offset) {
        if (row.dst.type == pad.dst.type && row.dst.index != pad.dst.index + offset)
            error(kPadRegister, row.dst.loc,
                  mn(row) + " must write " + regName(pad.dst.type, pad.dst.index + offset) + " after " + mn(pad) + " " +
                      regName(pad.dst.type, pad.dst.index) + " (" + lineRef(pad.loc) + "); found " +
                      regName(row.dst.type, row.dst.index));
        if (row.src[0].type != pad.src[0].type || row.src[0].index != pad.src[0].index)
            error(kPadSource, row.src[0].loc,
                  mn(row) + " must read the same source as " + mn(pad) + " (" + lineRef(pad.loc) +
                      "): " + regName(pad.src[0].type, pad.src[0].index) + ", found " +
                      regName(row.src[0].type, row.src[0].index));
    };
    size_t i = 0;
    while (i < n) {
        const Opcode op = opAt(i);
        if (op == Opcode::TexM3x2Pad) {
            if (!endsM3x2(opAt(i + 1))) {
                error(kPadSequence, inst(i).loc,
                      "texm3x2pad cannot be used by itself: the next instruction must be texm3x2tex or texm3x2depth "
                      "on the next register");
                ++i;
                continue;
            }
            checkRow(inst(i), inst(i + 1), 1);
            i += 2;
        } else if (op == Opcode::TexM3x3Pad) {
            if (opAt(i + 1) != Opcode::TexM3x3Pad) {
                error(kPadSequence, inst(i).loc,
                      "texm3x3pad cannot be used by itself: two texm3x3pad instructions must be followed by "
                      "texm3x3tex, texm3x3, texm3x3spec or texm3x3vspec");
                ++i;
                continue;
            }
            checkRow(inst(i), inst(i + 1), 1);
            if (!endsM3x3(opAt(i + 2))) {
                error(kPadSequence, inst(i + 1).loc,
                      "the second texm3x3pad must be followed by texm3x3tex, texm3x3, texm3x3spec or texm3x3vspec");
                i += 2;
                continue;
            }
            checkRow(inst(i), inst(i + 2), 2);
            i += 3;
        } else {
            if (endsM3x2(op) || endsM3x3(op))
                error(kMatrixWithoutPad, inst(i).loc,
                      mn(inst(i)) + " must directly follow " + (endsM3x2(op) ? "a texm3x2pad" : "two texm3x3pad") +
                          " instruction" + (endsM3x2(op) ? "" : "s") + " with the same source");
            ++i;
        }
    }
}
}  // namespace ps11::validator_detail
