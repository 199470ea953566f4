// The validator stage: checks an IR Program against every ps_1_1 … ps_1_4 rule of
// ps1x-spec.md §4 and fills ShaderStats. This file holds the driver, version legality,
// ordering, slot counting and the data-flow rules; operand rules are in validator_rules.cpp.
// All errors are collected (P2xxx, docs/diagnostics.md); nothing stops at the first one.
#include <algorithm>

#include "ps11/disassembler.h"
#include "ps11/validator_internal.h"

namespace ps11 {
namespace validator_detail {

bool Validator::checkVersion() {
    const Version& v = m_prog.version;
    if (v.major != 1 || v.minor < 1 || v.minor > 4) {
        error(kBadVersion, m_prog.versionLoc,
              "ps_" + std::to_string(v.major) + "_" + std::to_string(v.minor) +
                  " is not supported by this validator; it accepts ps_1_1, ps_1_2, ps_1_3 and ps_1_4");
        return false;
    }
    m_minor = v.minor;
    m_limits = limitsFor(m_minor);
    return true;
}

void Validator::computePhases() {
    const size_t n = m_prog.instructions.size();
    m_phaseOf.assign(n, is14() ? 2 : 0);
    if (!is14()) return;
    for (size_t i = 0; i < n; ++i) {
        if (inst(i).info && inst(i).opcode() == Opcode::Phase) {
            m_phaseInstruction = long(i);
            break;
        }
    }
    if (m_phaseInstruction < 0) return;  // no phase: the whole shader is phase 2 (spec §2.4)
    for (size_t i = 0; i < size_t(m_phaseInstruction); ++i) m_phaseOf[i] = 1;
}

// Instruction legal in the version (opcode row's version bits).
bool Validator::checkLegality(size_t i) {
    const Instruction& in = inst(i);
    if (in.info->versions & versionBit(m_minor)) return true;
    if (in.info->versions == 0) {
        error(kReservedOpcode, in.loc, mn(in) + " is a reserved opcode and invalid in every version");
        return false;
    }
    std::string msg = mn(in) + " is not available in " + vname() + " (only in " + versionList(in.info->versions) + ")";
    // Point at the same-token row of the version when there is one (tex → texld, texcoord → texcrd).
    for (const OpcodeInfo& row : opcodeTable())
        if (row.opcode == in.opcode() && (row.versions & versionBit(m_minor)) && row.mnemonic != in.info->mnemonic)
            msg += "; " + vname() + " uses " + std::string(row.mnemonic);
    error(kNotInVersion, in.loc, msg);
    return false;
}

void Validator::checkOrder(size_t i) {
    const Instruction& in = inst(i);
    const Opcode op = in.opcode();
    if (op == Opcode::Def) {
        if (m_seenNonDef) error(kDefAfterInstruction, in.loc, "def must come before every other instruction");
        return;
    }
    m_seenNonDef = true;
    if (op == Opcode::Phase) {
        if (long(i) != m_phaseInstruction)
            error(kSecondPhase, in.loc,
                  "only one phase instruction is allowed; the first is at " +
                      lineRef(inst(size_t(m_phaseInstruction)).loc));
        m_seenArith = false;  // phase 2 starts with its own texture block
        return;
    }
    if (isNop(in)) return;  // nop uses no slot and no pipe; it does not end the texture block
    if (isArith(in)) {
        if (!m_seenArith) m_firstArithLoc = in.loc;
        m_seenArith = true;
        return;
    }
    if (isTexture(in) && m_seenArith) {
        if (is14())
            error(kPhaseOrder, in.loc,
                  "texture instruction after an arithmetic instruction in phase " + std::to_string(m_phaseOf[i]) +
                      " (the arithmetic block starts at " + lineRef(m_firstArithLoc) +
                      "); ps_1_4 order is phase-1 texture, phase-1 arithmetic, phase, phase-2 texture, "
                      "phase-2 arithmetic");
        else
            error(kTexAfterArith, in.loc,
                  "texture instruction after an arithmetic instruction (at " + lineRef(m_firstArithLoc) + "); in " +
                      vname() + " every texture instruction must precede the arithmetic ones");
    }
}

void Validator::checkSlots(size_t i, InstructionStats& row) {
    const Instruction& in = inst(i);
    const size_t ph = m_phaseOf[i] == 1 ? 0 : 1;
    const std::string where = is14() ? " in phase " + std::to_string(ph + 1) : "";
    const std::string per = is14() ? " per phase" : "";
    row.texSlots = in.info->texSlots;
    row.arithSlots = pairsWithPrevious(i) ? 0 : arithCost(in);  // a pair counts as one slot (spec §3.5)
    if (row.texSlots > 0) {
        m_tex[ph] += row.texSlots;
        if (m_tex[ph] > m_limits.texSlots && !m_texReported[ph]) {
            m_texReported[ph] = true;
            error(kTexSlots, in.loc,
                  vname() + " allows " + std::to_string(m_limits.texSlots) + " texture instructions" + per +
                      "; this instruction makes " + std::to_string(m_tex[ph]) + where);
        }
    }
    if (row.arithSlots > 0) {
        m_arith[ph] += row.arithSlots;
        if (m_arith[ph] > m_limits.arithSlots && !m_arithReported[ph]) {
            m_arithReported[ph] = true;
            std::string cost = row.arithSlots > 1 ? " (" + mn(in) + " costs " + std::to_string(row.arithSlots) +
                                                        " slots in " + vname() + ")"
                                                  : "";
            if (in.opcode() == Opcode::TexBemL) cost = " (texbeml also uses an arithmetic slot)";
            error(kArithSlots, in.loc,
                  vname() + " allows " + std::to_string(m_limits.arithSlots) + " arithmetic slots" + per +
                      "; this instruction makes " + std::to_string(m_arith[ph]) + where + cost);
        }
    }
    // maxPerShader caps the instructions that are emulated with two slots (dp4/cmp in 1_2/1_3, bem);
    // in 1_4 dp4 and cmp cost one slot and are not capped (spec §4.1).
    const int count = ++m_opCount[size_t(in.opcode()) & 0xFF];
    if (in.info->maxPerShader > 0 && arithCost(in) >= 2 && count == in.info->maxPerShader + 1)
        error(kPerShaderCount, in.loc,
              vname() + " allows at most " + std::to_string(in.info->maxPerShader) + " " + mn(in) +
                  " per shader; this is number " + std::to_string(count));
}

void Validator::undefine(RegType type, int index, uint8_t comps, const std::string& why) {
    for (int c = 0; c < 4; ++c)
        if (comps & (1u << c)) m_regs[size_t(type)][size_t(index)][size_t(c)] = {false, why};
}

void Validator::readAccess(const Instruction& in, RegType type, int index, uint8_t comps, const SourceLoc& loc) {
    if (!inRange(type, index)) return;
    const std::string name = regName(type, index);
    if (type == RegType::Const) {
        m_constRead.insert(index);
        return;
    }
    if (!m_unusable[size_t(type)][size_t(index)].empty()) {
        error(kUnusableRegister, loc, name + " may not be used any more: " + m_unusable[size_t(type)][size_t(index)]);
        return;
    }
    const bool tracked = type == RegType::Temp || (type == RegType::Texture && !is14());
    if (tracked) {
        uint8_t missing = 0;
        std::string why;
        for (int c = 0; c < 4; ++c) {
            const Component& comp = m_regs[size_t(type)][size_t(index)][size_t(c)];
            if ((comps & (1u << c)) && !comp.defined) {
                missing |= uint8_t(1u << c);
                if (why.empty()) why = comp.why;
            }
        }
        if (missing)
            error(kUndefinedRead, loc,
                  name + "." + compList(missing) + " is read before it is written" + " (" +
                      (why.empty() ? "no earlier instruction writes it" : why) + ")");
    }
    if (type == RegType::Texture && !is14() && !m_bemRead[size_t(index)].empty() && in.opcode() != Opcode::TexBem &&
        in.opcode() != Opcode::TexBemL)
        error(kBemSourceReuse, loc,
              name + " was read by " + m_bemRead[size_t(index)] +
                  "; register data read by texbem/texbeml may be read only by another texbem/texbeml");
}

void Validator::dataflowReads(size_t i) {
    const Instruction& in = inst(i);
    const Opcode op = in.opcode();
    // Register components a source reads: the row's read set (opcode table), through the swizzle.
    auto swizzled = [&](const Src& src, int s) {
        const uint8_t channels = componentsRead(*in.info, s, in.dst.mask);
        uint8_t comps = 0;
        for (int c = 0; c < 4; ++c)
            if (channels & (1u << c)) comps |= uint8_t(1u << swizzleComponent(src.swizzle, c));
        return comps;
    };
    if (isArith(in)) {
        for (size_t s = 0; s < in.info->numSrc; ++s)
            readAccess(in, in.src[s].type, in.src[s].index, swizzled(in.src[s], int(s)), in.src[s].loc);
        return;
    }
    if (!isTexture(in)) return;
    if (!is14()) {
        // 1_1-1_3 texture sources take no selector (checked by the operand rules): the read set names
        // the register components. texkill's destination t(m) names coordinate set m, not the
        // register (spec §7.9): nothing of the register is read.
        for (size_t s = 0; s < in.info->numSrc; ++s)
            readAccess(in, in.src[s].type, in.src[s].index, componentsRead(*in.info, int(s), in.dst.mask),
                       in.src[s].loc);
        if ((op == Opcode::TexBem || op == Opcode::TexBemL) && in.src[0].type == RegType::Texture &&
            inRange(RegType::Texture, in.src[0].index))
            m_bemRead[in.src[0].index] = mn(in) + " at " + lineRef(in.loc);
        // Destination of a texture instruction: a dead register can't be reused.
        if (inRange(in.dst.type, in.dst.index) && !m_unusable[size_t(in.dst.type)][in.dst.index].empty())
            error(kUnusableRegister, in.dst.loc,
                  regName(in.dst.type, in.dst.index) +
                      " may not be used any more: " + m_unusable[size_t(in.dst.type)][in.dst.index]);
        return;
    }
    // ps_1_4.
    // ps_1_4: texkill and texdepth read the register their destination token names (dstReads);
    // texld reads its source through its selector; texcrd's source is a t# coordinate set (P2032
    // otherwise), whose components the read set names.
    if (in.info->dstReads) {
        readAccess(in, in.dst.type, in.dst.index, in.info->dstReads, in.dst.loc);
    } else if (in.info->numSrc >= 1) {
        const uint8_t comps =
            op == Opcode::Tex ? swizzled(in.src[0], 0) : componentsRead(*in.info, 0, in.dst.mask);
        readAccess(in, in.src[0].type, in.src[0].index, comps, in.src[0].loc);
        if (op == Opcode::Tex && m_phaseOf[i] == 2 && in.src[0].type == RegType::Temp &&
            inRange(RegType::Temp, in.src[0].index) && (m_writtenPhase2[in.src[0].index] & comps))
            error(kDependentRead, in.src[0].loc,
                  "texld reads " + regName(RegType::Temp, in.src[0].index) +
                      " written in phase 2; a dependent read uses r# values computed in phase 1");
    }
    // A destination that is read was checked above; a written one may not be a dead register.
    if (!in.info->dstReads && inRange(in.dst.type, in.dst.index) &&
        !m_unusable[size_t(in.dst.type)][in.dst.index].empty())
        error(kUnusableRegister, in.dst.loc,
              regName(in.dst.type, in.dst.index) +
                  " may not be used any more: " + m_unusable[size_t(in.dst.type)][in.dst.index]);
}

void Validator::writeAccess(RegType type, int index, uint8_t comps, int phase) {
    if (!inRange(type, index) || type == RegType::Const || type == RegType::Input) return;
    for (int c = 0; c < 4; ++c)
        if (comps & (1u << c)) m_regs[size_t(type)][size_t(index)][size_t(c)] = {true, {}};
    if (type == RegType::Temp && index == 0 && comps) m_r0Written = true;
    if (type == RegType::Temp && phase == 2) m_writtenPhase2[size_t(index)] |= comps;
    if (type == RegType::Texture) m_bemRead[size_t(index)].clear();  // new data in the register
}

void Validator::dataflowWrites(size_t i) {
    const Instruction& in = inst(i);
    const Opcode op = in.opcode();
    const int phase = m_phaseOf[i];
    const Dst& d = in.dst;
    if (op == Opcode::Phase) {
        for (int r = 0; r < registerCount(RegType::Temp, m_minor); ++r)
            if (m_regs[size_t(RegType::Temp)][size_t(r)][3].defined)
                undefine(RegType::Temp, r, kMaskA,
                         "the alpha of every r# is undefined after phase at " + lineRef(in.loc));
        return;
    }
    if (!in.info->hasDst || op == Opcode::Def || !inRange(d.type, d.index)) return;
    if (isArith(in)) {
        if (!m_unusable[size_t(d.type)][d.index].empty()) {
            error(kUnusableRegister, d.loc,
                  regName(d.type, d.index) + " may not be used any more: " + m_unusable[size_t(d.type)][d.index]);
            return;
        }
        writeAccess(d.type, d.index, d.mask & kMaskAll, phase);
        return;
    }
    const std::string at = mn(in) + " at " + lineRef(in.loc);
    if (!is14()) {
        if (in.info->writesDst) {
            writeAccess(d.type, d.index, kMaskAll, phase);
            return;
        }
        if (op == Opcode::TexM3x2Depth) {
            m_unusable[size_t(d.type)][d.index] = "it is the destination of " + at + ", which replaces the depth";
            return;
        }
        for (int c = 0; c < 4; ++c)
            if (!m_regs[size_t(d.type)][d.index][size_t(c)].defined)
                m_regs[size_t(d.type)][d.index][size_t(c)].why =
                    "only the destination of " + at + ", which does not write it";
        return;
    }
    if (op == Opcode::TexDepth) {
        m_unusable[size_t(d.type)][d.index] = "it was consumed by " + at;
        return;
    }
    if (op == Opcode::Tex) {
        writeAccess(d.type, d.index, kMaskAll, phase);
    } else if (op == Opcode::TexCoord) {
        // texcrd: the 4th channel is always undefined, the 3rd too for the _dw.xyw form (spec §2.4).
        uint8_t written = d.mask & kMaskRGB;
        if (in.src[0].mod == SrcMod::Dw) written &= uint8_t(~kMaskB);
        writeAccess(d.type, d.index, written, phase);
        const uint8_t lost = uint8_t(d.mask & kMaskAll & ~written);
        if (lost) undefine(d.type, d.index, lost, at + " leaves ." + compList(lost) + " undefined");
    }
}

void Validator::finish() {
    if (!m_opts.requireR0Written) return;
    if (!m_r0Written) {
        error(kR0NotWritten, m_prog.versionLoc, "the shader never writes r0, the output colour");
        return;
    }
    const auto& r0 = m_regs[size_t(RegType::Temp)][0];
    if (is14() && m_phaseInstruction >= 0 && !r0[3].defined) {
        error(kR0AlphaPhase, inst(size_t(m_phaseInstruction)).loc,
              "r0.a is not written after the phase instruction; the alpha of every r# is lost at phase, so phase 2 "
              "must write r0.a");
        return;
    }
    uint8_t missing = 0;
    for (int c = 0; c < 4; ++c)
        if (!r0[size_t(c)].defined) missing |= uint8_t(1u << c);
    if (missing)
        m_diags.warning(kR0Partial, m_prog.versionLoc,
                        "r0." + compList(missing) +
                            " is undefined when the shader ends; the output colour is partly "
                            "undefined");
}

bool Validator::run() {
    const size_t errorsBefore = m_diags.errorCount();
    m_stats = ShaderStats{};
    m_stats.version = m_prog.version;
    if (!checkVersion()) return false;
    m_stats.texLimit = m_limits.texSlots;
    m_stats.arithLimit = m_limits.arithSlots;
    m_stats.readPortLimit = m_limits.ports;
    computePhases();
    m_stats.hasPhase = m_phaseInstruction >= 0;
    const size_t n = m_prog.instructions.size();
    m_legal.assign(n, false);
    for (size_t i = 0; i < n; ++i) m_legal[i] = inst(i).info != nullptr && checkLegality(i);
    for (size_t i = 0; i < n; ++i) {
        const Instruction& in = inst(i);
        InstructionStats row;
        row.instruction = i;
        row.phase = m_phaseOf[i];
        row.coissue = in.coissue;
        row.loc = in.loc;
        row.text = in.info ? formatInstruction(in, m_prog.version) : std::string("<invalid>");
        if (legal(i)) {
            checkOrder(i);
            checkSlots(i, row);
            if (in.opcode() == Opcode::Def && in.dst.type == RegType::Const && inRange(RegType::Const, in.dst.index))
                m_constDefined.insert(in.dst.index);
            checkRegisters(i);
            checkMasks(i);
            checkSources(i);
            checkInstructionModifiers(i);
            checkCoissue(i);
            checkReadPorts(i);
            checkSpecial(i);
            checkTexRegisters(i);
            // Data flow: a co-issued pair reads all sources before either member writes (spec §3.5).
            dataflowReads(i);
            const bool pairFollows = isArith(in) && !in.coissue && i + 1 < n && inst(i + 1).coissue;
            if (m_pendingWrites < n) dataflowWrites(m_pendingWrites);  // the pair's first member writes now
            m_pendingWrites = SIZE_MAX;
            if (pairFollows)
                m_pendingWrites = i;
            else
                dataflowWrites(i);
        } else if (m_pendingWrites < n) {
            dataflowWrites(m_pendingWrites);
            m_pendingWrites = SIZE_MAX;
        }
        m_stats.table.push_back(std::move(row));
    }
    if (m_pendingWrites < n) dataflowWrites(m_pendingWrites);
    checkTexSequences();
    finish();

    m_stats.phaseTexSlots = m_tex;
    m_stats.phaseArithSlots = m_arith;
    m_stats.texSlots = m_tex[0] + m_tex[1];
    m_stats.arithSlots = m_arith[0] + m_arith[1];
    m_stats.dp4Count = m_opCount[size_t(Opcode::Dp4)];
    m_stats.cmpCount = m_opCount[size_t(Opcode::Cmp)];
    m_stats.bemCount = m_opCount[size_t(Opcode::Bem)];
    m_stats.constantsRead.assign(m_constRead.begin(), m_constRead.end());
    m_stats.constantsDefined.assign(m_constDefined.begin(), m_constDefined.end());
    m_stats.valid = m_diags.errorCount() == errorsBefore;
    return m_stats.valid;
}

}  // namespace validator_detail

bool validate(const Program& program, Diagnostics& diags, ShaderStats* stats, const ValidateOptions& options) {
    ShaderStats local;
    validator_detail::Validator v(program, diags, options, stats ? *stats : local);
    return v.run();
}

}  // namespace ps11
