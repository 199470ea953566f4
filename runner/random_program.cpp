// Random ps_1_x cases for differential fuzzing (runner/random_program.h). Programs are built as
// IR instructions from the opcode table's rows for the version and written by the
// disassembler's formatInstruction; each instruction (or texm3x2/texm3x3 sequence, or co-issued
// pair) is kept only when the program so far still validates without a diagnostic, so the
// validator, not this file, is the judge of every rule. The generator tracks only what it needs
// to pick sources that are likely to be accepted: which register components are written. The
// test file around a program is runner/random_environment.cpp's; the shrinker here reduces the
// program as IR and the environment as lines of that text.
#include "runner/random_program.h"

#include "runner/random_case_internal.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdio>
#include <optional>

#include "ps11/assembler.h"
#include "ps11/disassembler.h"
#include "ps11/ir.h"
#include "ps11/opcodes.h"
#include "ps11/token_format.h"
#include "ps11/validator.h"

namespace ps11test {

using ps11::Instruction;
using ps11::OpClass;
using ps11::Opcode;
using ps11::OpcodeInfo;
using ps11::RegType;
using ps11::SrcMod;

namespace {

constexpr uint8_t swizzleOf(int x, int y, int z, int w) { return uint8_t(x | y << 2 | z << 4 | w << 6); }
constexpr uint8_t kSwizzleXyz = swizzleOf(0, 1, 2, 2);
constexpr uint8_t kSwizzleXyw = swizzleOf(0, 1, 3, 3);

constexpr uint8_t bit(int index) { return uint8_t(1u << index); }

// The table's rows of a class that are legal in the version and have a destination (nop has
// none and does nothing worth generating).
std::vector<const OpcodeInfo*> rowsOf(int minor, OpClass cls) {
    std::vector<const OpcodeInfo*> rows;
    for (const OpcodeInfo& row : ps11::opcodeTable())
        if (row.cls == cls && row.hasDst && (row.versions & ps11::versionBit(minor))) rows.push_back(&row);
    return rows;
}

const OpcodeInfo& rowOf(Opcode op, int minor) {
    for (const OpcodeInfo& row : ps11::opcodeTable())
        if (row.opcode == op && (row.versions & ps11::versionBit(minor))) return row;
    return ps11::opcodeTable().front();  // not reached: def, phase and mov rows exist where they are asked for
}

// Where a 1_1-1_3 texture-address row stands: alone, first row of a texm3x2/texm3x3 sequence,
// or only as the row that ends one (spec §2.3).
enum class Shape { Alone, Pad, EndsM3x2, EndsM3x3 };

Shape shapeOf(Opcode op) {
    switch (op) {
        case Opcode::TexM3x2Pad:
        case Opcode::TexM3x3Pad:
            return Shape::Pad;
        case Opcode::TexM3x2Tex:
        case Opcode::TexM3x2Depth:
            return Shape::EndsM3x2;
        case Opcode::TexM3x3Tex:
        case Opcode::TexM3x3:
        case Opcode::TexM3x3Spec:
        case Opcode::TexM3x3VSpec:
            return Shape::EndsM3x3;
        default:
            return Shape::Alone;
    }
}

Instruction instructionOf(const OpcodeInfo& row) {
    Instruction in;
    in.info = &row;
    return in;
}

ps11::Src sourceOf(RegType type, int index, SrcMod mod = SrcMod::None, uint8_t swizzle = ps11::tok::kIdentitySwizzle) {
    ps11::Src s;
    s.type = type;
    s.index = uint8_t(index);
    s.mod = mod;
    s.swizzle = swizzle;
    return s;
}

ps11::Dst destinationOf(RegType type, int index, uint8_t mask = ps11::kMaskAll) {
    ps11::Dst d;
    d.type = type;
    d.index = uint8_t(index);
    d.mask = mask;
    return d;
}

// No diagnostic at all from the validator.
bool validatesCleanly(const ps11::Program& program, bool requireR0, ps11::ShaderStats* stats = nullptr) {
    ps11::Diagnostics diags;
    ps11::ValidateOptions options;
    options.requireR0Written = requireR0;
    ps11::validate(program, diags, stats, options);
    return diags.all().empty();
}

// r0/v0/c0 … with index 0, no modifier and no selector.
bool isBare(const ps11::Src& s, RegType type) {
    return s.type == type && s.index == 0 && s.mod == SrcMod::None && s.swizzle == ps11::tok::kIdentitySwizzle;
}

std::optional<ps11::Program> assembleCleanly(const std::string& text) {
    ps11::Diagnostics diags;
    std::optional<ps11::Program> program = ps11::parseAssembly(text, "random.psh", {}, diags);
    if (!program || !diags.all().empty() || !validatesCleanly(*program, true)) return std::nullopt;
    return program;
}

std::string shaderTextOf(int minor, const std::vector<std::string>& lines) {
    std::string text = "ps_1_" + std::to_string(minor);
    for (const std::string& line : lines) text += "\n" + line;
    return text;
}

std::vector<std::string> linesOf(const std::vector<Instruction>& code, int minor) {
    std::vector<std::string> lines;
    for (const Instruction& in : code) lines.push_back(ps11::formatInstruction(in, {1, minor}));
    return lines;
}

// Builds one program. Every attempt to add an instruction validates the program so far
// (without requiring r0 yet) and keeps the addition only when there is no diagnostic.
class Generator {
public:
    Generator(Dice& dice, int minor, int maxArith) : m_dice(dice), m_minor(minor), m_maxArith(std::max(1, maxArith)) {}

    std::vector<Instruction> run();

private:
    static constexpr int kAttempts = 24;  // tries per instruction before it is left out

    bool is14() const { return m_minor == 4; }
    int registers(RegType type) const { return ps11::registerCount(type, m_minor); }
    uint8_t& defined(RegType type, int index) { return m_defined[size_t(type)][size_t(index)]; }
    bool usable(RegType type, int index) const { return !(m_unusable[size_t(type)] & bit(index)); }

    bool validatesWith(const std::vector<Instruction>& more, ps11::ShaderStats& stats) const;
    int arithSlotsLeft() const;
    bool tryAppend(const std::vector<Instruction>& more, int reserveSlots);
    void record(const Instruction& in);
    void write(RegType type, int index, uint8_t mask);

    void defs();
    void textureBlock13();
    std::vector<Instruction> texture13(int stage);
    std::optional<ps11::Src> textureSource13(int stage, Opcode op);
    void textureBlock14();
    std::vector<Instruction> texture14();
    std::optional<ps11::Src> coordinateSource();
    void arithBlock(int count, bool endsProgram);
    std::vector<Instruction> arithUnit(bool pair, bool final);
    uint8_t singleMask(const OpcodeInfo& row);
    ps11::Src arithSource(uint8_t channels, uint8_t mask);

    Dice& m_dice;
    const int m_minor;
    const int m_maxArith;
    std::vector<Instruction> m_code;
    int m_phase = 0;  // ps_1_4: 1 before the phase instruction, 2 after it (or without one); 0 in 1_1-1_3
    // Written components per register (bit 0 = r … bit 3 = a), indexed by RegType.
    std::array<std::array<uint8_t, 8>, 4> m_defined{};
    std::array<uint8_t, 4> m_unusable{};  // registers the validator retires (texm3x2depth, texdepth)
    uint8_t m_bemSources = 0;             // 1_1-1_3 t# read by texbem/texbeml
    uint8_t m_textureDsts = 0;            // t# (1_1-1_3) or, in this phase, r# (1_4) a texture instruction wrote
    uint8_t m_phase2Writes = 0;           // ps_1_4 r# written in phase 2
    std::array<uint8_t, 8> m_coordinateSelector{};  // ps_1_4 t#: 0 unread, else the swizzle texld/texcrd read it with
    int m_dzUses = 0;
};

// The program so far plus `more` validates without a diagnostic. In ps_1_4 phase 1 a phase
// instruction is added after them, so that the validator sees phase-1 code as phase 1.
bool Generator::validatesWith(const std::vector<Instruction>& more, ps11::ShaderStats& stats) const {
    ps11::Program program;
    program.version = {1, m_minor};
    program.instructions = m_code;
    program.instructions.insert(program.instructions.end(), more.begin(), more.end());
    if (m_phase == 1) program.instructions.push_back(instructionOf(rowOf(Opcode::Phase, 4)));
    return validatesCleanly(program, false, &stats);
}

// Arithmetic slots the version leaves in the current phase (the whole shader in 1_1-1_3).
int Generator::arithSlotsLeft() const {
    ps11::ShaderStats stats;
    validatesWith({}, stats);
    return stats.arithLimit - (is14() ? stats.phaseArithSlots[size_t(m_phase - 1)] : stats.arithSlots);
}

bool Generator::tryAppend(const std::vector<Instruction>& more, int reserveSlots) {
    ps11::ShaderStats stats;
    if (!validatesWith(more, stats)) return false;
    const int used = is14() ? stats.phaseArithSlots[size_t(m_phase - 1)] : stats.arithSlots;
    if (stats.arithLimit - used < reserveSlots) return false;
    m_code.insert(m_code.end(), more.begin(), more.end());
    for (const Instruction& in : more) record(in);
    return true;
}

void Generator::write(RegType type, int index, uint8_t mask) {
    defined(type, index) |= mask;
    if (type == RegType::Temp && m_phase == 2) m_phase2Writes |= bit(index);
    if (type == RegType::Texture) m_bemSources &= uint8_t(~bit(index));  // new data in the register
}

// What an accepted instruction leaves defined or retired (spec §2.3, §2.4).
void Generator::record(const Instruction& in) {
    const Opcode op = in.opcode();
    const ps11::Dst& d = in.dst;
    if (op == Opcode::Phase) {
        for (auto& r : m_defined[size_t(RegType::Temp)]) r &= uint8_t(~ps11::kMaskA);  // alpha is lost at phase
        m_phase = 2;
        m_textureDsts = 0;
        return;
    }
    if (op == Opcode::Def) return;
    if (in.info->cls == OpClass::Arith) {
        write(d.type, d.index, d.mask);
        return;
    }
    if (!is14()) {
        m_textureDsts |= bit(d.index);  // each t# takes one texture instruction
        if (op == Opcode::TexBem || op == Opcode::TexBemL) m_bemSources |= bit(in.src[0].index);
        if (op == Opcode::TexM3x2Depth)
            m_unusable[size_t(d.type)] |= bit(d.index);
        else if (in.info->writesDst)
            write(d.type, d.index, ps11::kMaskAll);
        return;
    }
    const ps11::Src& s = in.src[0];
    if (in.info->numSrc > 0 && s.type == RegType::Texture) m_coordinateSelector[s.index] = s.swizzle;
    if (in.info->numSrc > 0 && s.mod == SrcMod::Dz) ++m_dzUses;
    if (op == Opcode::Tex || op == Opcode::TexCoord) m_textureDsts |= bit(d.index);
    if (op == Opcode::Tex) {
        write(d.type, d.index, ps11::kMaskAll);
    } else if (op == Opcode::TexCoord) {
        // texcrd writes x, y, z of its mask; w stays undefined, and z too with _dw.xyw.
        uint8_t written = d.mask & ps11::kMaskRGB;
        if (s.mod == SrcMod::Dw) written &= uint8_t(~ps11::kMaskB);
        defined(d.type, d.index) &= uint8_t(~d.mask);
        write(d.type, d.index, written);
    } else if (op == Opcode::TexDepth) {
        m_unusable[size_t(d.type)] |= bit(d.index);
    }
}

std::vector<Instruction> Generator::run() {
    m_phase = is14() ? 2 : 0;
    defs();
    const int arith = m_dice.range(1, m_maxArith);
    if (!is14()) {
        textureBlock13();
        arithBlock(arith, true);
        return m_code;
    }
    if (m_dice.chance(50)) {
        m_phase = 1;
        const int phase1 = m_dice.range(0, arith - 1);
        textureBlock14();
        arithBlock(phase1, false);
        // Phase 1 was validated with this phase instruction after it all along.
        m_code.push_back(instructionOf(rowOf(Opcode::Phase, 4)));
        record(m_code.back());
        textureBlock14();
        arithBlock(arith - phase1, true);
        return m_code;
    }
    textureBlock14();
    arithBlock(arith, true);
    return m_code;
}

void Generator::defs() {
    const int count = m_dice.range(0, 2);
    const int first = m_dice.below(size_t(registers(RegType::Const)));
    for (int k = 0; k < count; ++k) {
        Instruction def = instructionOf(rowOf(Opcode::Def, m_minor));
        def.dst = destinationOf(RegType::Const, (first + k) % registers(RegType::Const));
        for (uint32_t& bits : def.defBits) bits = std::bit_cast<uint32_t>(float(m_dice.thousandths(-1, 1)));
        tryAppend({def}, 0);
    }
}

void Generator::textureBlock13() {
    for (int stage = 0; stage < registers(RegType::Texture); ++stage) {
        if ((m_textureDsts & bit(stage)) || !m_dice.chance(65)) continue;
        for (int attempt = 0; attempt < kAttempts; ++attempt) {
            std::vector<Instruction> more = texture13(stage);
            if (!more.empty() && tryAppend(more, 1)) break;
        }
    }
}

// A texture-address instruction (or a whole texm3x2/texm3x3 sequence) that starts at t<stage>.
std::vector<Instruction> Generator::texture13(int stage) {
    // Rows of pads before the row that ends the sequence.
    auto padsOf = [](Opcode op) { return op == Opcode::TexM3x2Pad ? 1 : 2; };
    std::vector<const OpcodeInfo*> alone, sequences;  // sequences that fit below the last stage
    for (const OpcodeInfo* row : rowsOf(m_minor, OpClass::Texture)) {
        const Shape shape = shapeOf(row->opcode);
        if (shape == Shape::Alone)
            alone.push_back(row);
        else if (shape == Shape::Pad && stage + padsOf(row->opcode) < registers(RegType::Texture))
            sequences.push_back(row);
    }
    const OpcodeInfo& row = *m_dice.pick(!sequences.empty() && m_dice.chance(50) ? sequences : alone);
    Instruction first = instructionOf(row);
    first.dst = destinationOf(RegType::Texture, stage);
    if (row.numSrc == 0) return {first};
    std::optional<ps11::Src> source = textureSource13(stage, row.opcode);
    if (!source) return {};
    first.src[0] = *source;
    if (shapeOf(row.opcode) != Shape::Pad) return {first};
    const int pads = padsOf(row.opcode);
    const Shape ends = pads == 1 ? Shape::EndsM3x2 : Shape::EndsM3x3;
    std::vector<const OpcodeInfo*> enders;
    for (const OpcodeInfo* r : rowsOf(m_minor, OpClass::Texture))
        if (shapeOf(r->opcode) == ends) enders.push_back(r);
    std::vector<Instruction> sequence;
    for (int k = 0; k < pads; ++k) {
        sequence.push_back(first);
        sequence.back().dst.index = uint8_t(stage + k);
    }
    Instruction last = instructionOf(*m_dice.pick(enders));
    last.dst = destinationOf(RegType::Texture, stage + pads);
    last.src[0] = *source;
    // texm3x3spec's second source is the eye vector, a constant.
    if (last.info->numSrc > 1) last.src[1] = sourceOf(RegType::Const, m_dice.below(size_t(registers(RegType::Const))));
    sequence.push_back(last);
    return sequence;
}

// A t# below the stage that a texture instruction wrote, sometimes with _bx2.
std::optional<ps11::Src> Generator::textureSource13(int stage, Opcode op) {
    const bool bem = op == Opcode::TexBem || op == Opcode::TexBemL;
    std::vector<int> candidates;
    for (int n = 0; n < stage; ++n)
        if (defined(RegType::Texture, n) == ps11::kMaskAll && usable(RegType::Texture, n) &&
            (bem || !(m_bemSources & bit(n))))
            candidates.push_back(n);
    if (candidates.empty()) return std::nullopt;
    return sourceOf(RegType::Texture, m_dice.pick(candidates), m_dice.chance(30) ? SrcMod::Sign : SrcMod::None);
}

void Generator::textureBlock14() {
    const int count = m_dice.range(m_phase == 1 ? 1 : 0, 3);
    for (int k = 0; k < count; ++k)
        for (int attempt = 0; attempt < kAttempts; ++attempt) {
            std::vector<Instruction> more = texture14();
            if (!more.empty() && tryAppend(more, 0)) break;
        }
}

// texld, texcrd, texkill or texdepth in the current phase's texture block.
std::vector<Instruction> Generator::texture14() {
    const OpcodeInfo& row = *m_dice.pick(rowsOf(4, OpClass::Texture));
    Instruction in = instructionOf(row);
    std::vector<int> free;  // r# no texture instruction of this phase wrote yet
    for (int r = 0; r < registers(RegType::Temp); ++r)
        if (!(m_textureDsts & bit(r)) && usable(RegType::Temp, r)) free.push_back(r);
    switch (row.opcode) {
        case Opcode::Tex: {
            if (free.empty()) return {};
            in.dst = destinationOf(RegType::Temp, m_dice.pick(free));
            // A dependent read (phase 2) of an r# that phase 1 computed.
            std::vector<int> computed;
            for (int r = 0; r < registers(RegType::Temp); ++r)
                if ((defined(RegType::Temp, r) & ps11::kMaskRGB) == ps11::kMaskRGB && !(m_phase2Writes & bit(r)) &&
                    usable(RegType::Temp, r))
                    computed.push_back(r);
            if (m_phase == 2 && !computed.empty() && m_dice.chance(40)) {
                const SrcMod mod = m_dzUses < 2 && m_dice.chance(30) ? SrcMod::Dz : SrcMod::None;
                in.src[0] = sourceOf(RegType::Temp, m_dice.pick(computed), mod,
                                     m_dice.chance(50) ? kSwizzleXyz : ps11::tok::kIdentitySwizzle);
                return {in};
            }
            std::optional<ps11::Src> source = coordinateSource();
            if (!source) return {};
            in.src[0] = *source;
            return {in};
        }
        case Opcode::TexCoord: {
            if (free.empty()) return {};
            static const std::vector<uint8_t> kMasks = {ps11::kMaskAll, ps11::kMaskRGB, ps11::kMaskR | ps11::kMaskG};
            in.dst = destinationOf(RegType::Temp, m_dice.pick(free), m_dice.pick(kMasks));
            std::optional<ps11::Src> source = coordinateSource();
            if (!source) return {};
            in.src[0] = *source;
            return {in};
        }
        case Opcode::TexKill: {
            const int r = m_dice.below(size_t(registers(RegType::Temp)));
            if (m_dice.chance(50) && (defined(RegType::Temp, r) & ps11::kMaskRGB) == ps11::kMaskRGB)
                in.dst = destinationOf(RegType::Temp, r);
            else
                in.dst = destinationOf(RegType::Texture, m_dice.below(size_t(registers(RegType::Texture))));
            return {in};
        }
        case Opcode::TexDepth:
            // Works on r5 only, in phase 2 (spec §2.4).
            in.dst = destinationOf(RegType::Temp, registers(RegType::Temp) - 1);
            return {in};
        default:
            return {};
    }
}

// A t# as texld/texcrd read it: .xyz (or no selector) or .xyw (or _dw.xyw), the same kind for
// every read of one t#.
std::optional<ps11::Src> Generator::coordinateSource() {
    const int t = m_dice.below(size_t(registers(RegType::Texture)));
    const uint8_t before = m_coordinateSelector[size_t(t)];
    const bool xyw = before ? before == kSwizzleXyw : m_dice.chance(40);
    if (xyw) return sourceOf(RegType::Texture, t, m_dice.chance(50) ? SrcMod::Dw : SrcMod::None, kSwizzleXyw);
    return sourceOf(RegType::Texture, t, SrcMod::None, m_dice.chance(50) ? kSwizzleXyz : ps11::tok::kIdentitySwizzle);
}

// `count` arithmetic instructions; when endsProgram, the last one (or the last pair) writes the
// whole of r0, and every earlier one leaves it an arithmetic slot.
void Generator::arithBlock(int count, bool endsProgram) {
    int done = 0;
    while (done < count) {
        // Out of slots: straight to the final unit, or the end of the block.
        const int left = arithSlotsLeft();
        if (endsProgram && done + 1 < count && left <= 1) {
            done = count - 1;
            continue;
        }
        if (!endsProgram && left <= 0) return;
        bool added = false;
        for (int attempt = 0; attempt < kAttempts && !added; ++attempt) {
            const bool pair = count - done >= 2 && m_dice.chance(25);
            const int size = pair ? 2 : 1;
            const bool final = endsProgram && done + size == count;
            std::vector<Instruction> unit = arithUnit(pair, final);
            if (!unit.empty() && tryAppend(unit, endsProgram && !final ? 1 : 0)) {
                done += size;
                added = true;
            }
        }
        if (added) continue;
        if (endsProgram && done + 1 == count) {
            Instruction mov = instructionOf(rowOf(Opcode::Mov, m_minor));
            mov.dst = destinationOf(RegType::Temp, 0);
            mov.src[0] = sourceOf(RegType::Input, 0);
            tryAppend({mov}, 0);
        }
        ++done;
    }
}

uint8_t Generator::singleMask(const OpcodeInfo& row) {
    if (row.opcode == Opcode::Bem) return ps11::kMaskR | ps11::kMaskG;  // bem writes .rg exactly
    if (is14()) return m_dice.chance(50) ? uint8_t(ps11::kMaskAll) : uint8_t(m_dice.range(1, 15));
    const int roll = m_dice.below(100);
    return roll < 60 ? ps11::kMaskAll : roll < 85 ? ps11::kMaskRGB : ps11::kMaskA;
}

// One arithmetic instruction, or a co-issued pair (one member writes colour, the other alpha,
// in either order). A final unit writes all of r0.
std::vector<Instruction> Generator::arithUnit(bool pair, bool final) {
    std::vector<const OpcodeInfo*> rows;
    for (const OpcodeInfo* row : rowsOf(m_minor, OpClass::Arith))
        if (!pair || row->coissuable) rows.push_back(row);
    const bool alphaFirst = m_dice.chance(50);
    std::vector<Instruction> unit;
    for (int member = 0; member < (pair ? 2 : 1); ++member) {
        const OpcodeInfo& row = *m_dice.pick(rows);
        Instruction in = instructionOf(row);
        in.coissue = member == 1;
        uint8_t mask;
        if (!pair)
            mask = final ? uint8_t(ps11::kMaskAll) : singleMask(row);
        else if ((member == 0) == alphaFirst)
            mask = ps11::kMaskA;
        else
            mask = final || !is14() ? uint8_t(ps11::kMaskRGB) : uint8_t(m_dice.range(1, 7));
        // 1_1-1_3 arithmetic may write t# too.
        const RegType type = !final && !is14() && m_dice.chance(15) ? RegType::Texture : RegType::Temp;
        const int index = final ? 0 : m_dice.below(size_t(registers(type)));
        if (!usable(type, index)) return {};
        in.dst = destinationOf(type, index, mask);
        static const std::vector<int> kShifts13 = {1, 2, -1}, kShifts14 = {1, 2, 3, -1, -2, -3};
        if (m_dice.chance(30)) in.dst.shift = int8_t(m_dice.pick(is14() ? kShifts14 : kShifts13));
        in.dst.saturate = m_dice.chance(25);
        // The components each source gives: what the operation reads, else the write mask.
        const uint8_t channels = ps11::componentsReadAny(row, mask);
        for (size_t s = 0; s < row.numSrc; ++s) in.src[s] = arithSource(channels, mask);
        // The 1_1-1_3 cnd condition is r0.a exactly (spec §2.2).
        if (row.opcode == Opcode::Cnd && !is14())
            in.src[0] = sourceOf(RegType::Temp, 0, SrcMod::None, swizzleOf(3, 3, 3, 3));
        unit.push_back(in);
    }
    return unit;
}

// A source whose components the instruction reads are written: r#, 1_1-1_3 t#, v# (not in
// ps_1_4 phase 1) or c#, with a selector and (not on c#, where it is undefined or invalid) a
// source modifier the version has.
ps11::Src Generator::arithSource(uint8_t channels, uint8_t mask) {
    uint8_t swizzle = ps11::tok::kIdentitySwizzle;
    if (is14()) {
        if (m_dice.chance(40)) {
            const int c = m_dice.below(4);
            swizzle = swizzleOf(c, c, c, c);
        }
    } else {
        const int roll = m_dice.below(100);
        if (roll < 20)
            swizzle = swizzleOf(3, 3, 3, 3);
        else if (roll < 30 && mask == ps11::kMaskA)
            swizzle = swizzleOf(2, 2, 2, 2);
    }
    uint8_t needed = 0;
    for (int c = 0; c < 4; ++c)
        if (channels & bit(c)) needed |= bit(ps11::swizzleComponent(swizzle, c));
    std::vector<std::vector<ps11::Src>> pools(3);  // written registers, inputs, constants
    for (RegType type : {RegType::Temp, RegType::Texture}) {
        if (type == RegType::Texture && is14()) continue;
        for (int i = 0; i < registers(type); ++i)
            if ((defined(type, i) & needed) == needed && usable(type, i) &&
                !(type == RegType::Texture && (m_bemSources & bit(i))))
                pools[0].push_back(sourceOf(type, i));
    }
    if (m_phase != 1)
        for (int i = 0; i < registers(RegType::Input); ++i) pools[1].push_back(sourceOf(RegType::Input, i));
    for (int i = 0; i < registers(RegType::Const); ++i) pools[2].push_back(sourceOf(RegType::Const, i));
    std::vector<size_t> filled;
    for (size_t p = 0; p < pools.size(); ++p)
        if (!pools[p].empty()) filled.push_back(p);
    ps11::Src src = m_dice.pick(pools[m_dice.pick(filled)]);
    src.swizzle = swizzle;
    if (src.type != RegType::Const && m_dice.chance(50)) {
        // SrcMod values Neg … X2Neg; _x2 and -_x2 are ps_1_4's.
        const int last = int(is14() ? SrcMod::X2Neg : SrcMod::Comp);
        src.mod = SrcMod(m_dice.range(int(SrcMod::Neg), last));
    }
    return src;
}

}  // namespace

std::string RandomCase::shaderText() const { return shaderTextOf(minor, lines); }

bool isCleanProgram(int minor, const std::vector<std::string>& lines) {
    return assembleCleanly(shaderTextOf(minor, lines)).has_value();
}

RandomCase randomCase(std::mt19937_64& rng, const RandomCaseOptions& options) {
    Dice dice(rng);
    RandomCase c;
    c.minor = options.minor >= 1 && options.minor <= 4 ? options.minor : dice.range(1, 4);
    std::optional<ps11::Program> program;
    // Each instruction was validated as it was added, so the whole program rarely fails; a
    // final unit left out (or a warning only the whole program shows) gets a new program.
    for (int attempt = 0; attempt < 8 && !program; ++attempt) {
        c.lines = linesOf(Generator(dice, c.minor, options.maxArith).run(), c.minor);
        program = assembleCleanly(c.shaderText());
    }
    if (!program) {
        c.lines = {"mov r0, v0"};
        program = assembleCleanly(c.shaderText());
    }
    c.testText =
        testTextOf(dice, *program, c.shaderText(), std::max(1, options.width), std::max(1, options.height), true);
    return c;
}

RandomCase caseForProgram(std::mt19937_64& rng, int minor, const std::vector<std::string>& lines,
                          const RandomCaseOptions& options) {
    Dice dice(rng);
    RandomCase c;
    c.minor = minor;
    c.lines = lines;
    // A user's shader may carry warnings; errors leave the case empty.
    ps11::Diagnostics diags;
    std::optional<ps11::Program> program = ps11::parseAssembly(c.shaderText(), "shader.psh", {}, diags);
    if (program) ps11::validate(*program, diags);
    if (program && !diags.hasErrors())
        c.testText =
            testTextOf(dice, *program, c.shaderText(), std::max(1, options.width), std::max(1, options.height), false);
    return c;
}

std::string caseTestText(const RandomCase& c) {
    const std::string section = "[pixel shader]\n";
    const std::string& text = c.testText;
    const size_t at = text.find(section);
    if (at == std::string::npos) return text + "\n" + section + c.shaderText() + "\n";
    const size_t begin = at + section.size();
    const size_t end = text.find("\n[", begin);  // the next section line
    return text.substr(0, begin) + c.shaderText() + "\n" + (end == std::string::npos ? "" : text.substr(end));
}

RandomCase shrinkCase(const RandomCase& start, const std::function<bool(const RandomCase&)>& stillFails) {
    std::optional<ps11::Program> program = assembleCleanly(start.shaderText());
    if (!program) return start;
    RandomCase best = start;
    std::vector<Instruction> code = program->instructions;
    // Keeps `candidate` (in the environment kept so far) when it is clean and still fails.
    auto keep = [&](const std::vector<Instruction>& candidate) {
        RandomCase c = best;
        c.lines = linesOf(candidate, start.minor);
        if (!isCleanProgram(c.minor, c.lines)) return false;
        c.testText = caseTestText(c);
        if (!stillFails(c)) return false;
        best = std::move(c);
        code = candidate;
        return true;
    };
    for (bool progress = true; progress;) {
        progress = false;
        // Runs of lines of every length from half the program (rounded up) down to one line, at
        // every place: a texm3x3 sequence goes only as a whole, with or without its source.
        for (size_t run = (code.size() + 1) / 2; run >= 1; --run) {
            for (size_t i = 0; i + run <= code.size();) {
                std::vector<Instruction> candidate = code;
                candidate.erase(candidate.begin() + long(i), candidate.begin() + long(i + run));
                if (keep(candidate))
                    progress = true;
                else
                    ++i;
            }
        }
        // Simpler forms of each instruction, the boldest first.
        for (size_t i = 0; i < code.size(); ++i) {
            std::vector<std::vector<Instruction>> candidates;
            auto variant = [&](auto change) {
                std::vector<Instruction> candidate = code;
                change(candidate[i]);
                candidates.push_back(std::move(candidate));
            };
            const Instruction& in = code[i];
            if (in.opcode() == Opcode::Def) continue;
            for (size_t s = 0; s < in.info->numSrc; ++s) {
                // A bare c0 is the simplest source, a bare v0 the next: a source is replaced only by a
                // simpler one, so the passes end.
                for (RegType type : {RegType::Const, RegType::Input}) {
                    if (isBare(in.src[s], type)) break;
                    variant([&](Instruction& x) { x.src[s] = sourceOf(type, 0); });
                }
                if (in.src[s].mod != SrcMod::None) variant([&](Instruction& x) { x.src[s].mod = SrcMod::None; });
                if (in.src[s].swizzle != ps11::tok::kIdentitySwizzle)
                    variant([&](Instruction& x) { x.src[s].swizzle = ps11::tok::kIdentitySwizzle; });
            }
            // r0 is the simplest destination, and no write mask the simplest mask.
            if (in.dst.type != RegType::Temp || in.dst.index != 0)
                variant([](Instruction& x) { x.dst = destinationOf(RegType::Temp, 0, x.dst.mask); });
            if (in.dst.mask != ps11::kMaskAll) variant([](Instruction& x) { x.dst.mask = ps11::kMaskAll; });
            if (in.coissue) variant([](Instruction& x) { x.coissue = false; });
            if (in.dst.shift != 0) variant([](Instruction& x) { x.dst.shift = 0; });
            if (in.dst.saturate) variant([](Instruction& x) { x.dst.saturate = false; });
            for (const std::vector<Instruction>& candidate : candidates)
                if (keep(candidate)) {
                    progress = true;
                    break;  // code[i] changed: its other variants are rebuilt next pass
                }
        }
        // The environment: sections, extra triangles, state lines, mip chains, perspective and
        // depth, each kept out when the file still parses and still fails. After a success the
        // list is rebuilt from the smaller file and the walk goes on at the same place.
        std::vector<std::string> texts = simplerEnvironments(best.testText);
        for (size_t i = 0; i < texts.size();) {
            RandomCase c = best;
            c.testText = texts[i];
            if (c.testText != best.testText && parsesAsTestFile(c.testText) && stillFails(c)) {
                best = std::move(c);
                progress = true;
                texts = simplerEnvironments(best.testText);
            } else {
                ++i;
            }
        }
    }
    return best;
}

}  // namespace ps11test
