// Random ps_1_x cases for differential fuzzing (runner/random_program.h). Programs are built as
// IR instructions from the opcode table's rows for the version and written by the
// disassembler's formatInstruction; each instruction (or texm3x2/texm3x3 sequence, or co-issued
// pair) is kept only when the program so far still validates without a diagnostic, so the
// validator, not this file, is the judge of every rule. The generator tracks only what it needs
// to pick sources that are likely to be accepted: which register components are written. The
// test file around a program is written as text (docs/test-format.md), with the environment of
// randomCase drawn feature by feature (runner/random_program.h); the shrinker reduces the program
// as IR and the environment as lines of that text.
#include "runner/random_program.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdio>
#include <optional>

#include "ps11/assembler.h"
#include "ps11/disassembler.h"
#include "ps11/formats.h"
#include "ps11/hardware.h"
#include "ps11/ir.h"
#include "ps11/opcodes.h"
#include "ps11/testfile.h"
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

// Uniform draws from the engine's raw output rather than std::uniform_*_distribution, whose
// algorithms differ between standard libraries: a seed gives the same case everywhere.
class Dice {
public:
    explicit Dice(std::mt19937_64& rng) : m_rng(rng) {}
    int below(size_t n) { return int(m_rng() % n); }
    int range(int lo, int hi) { return lo + below(size_t(hi - lo + 1)); }
    bool chance(int percent) { return below(100) < percent; }
    uint32_t word() { return uint32_t(m_rng() >> 32); }
    // A multiple of 1/1000 in [lo, hi].
    double thousandths(double lo, double hi) { return range(int(lo * 1000), int(hi * 1000)) / 1000.0; }
    template <class T>
    const T& pick(const std::vector<T>& v) {
        return v[size_t(below(v.size()))];
    }

private:
    std::mt19937_64& m_rng;
};

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
        uint8_t channels = mask;
        if (row.opcode == Opcode::Dp3) channels = ps11::kMaskRGB;
        if (row.opcode == Opcode::Dp4) channels = ps11::kMaskAll;
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

// ---------------------------------------------------------------- the test file

// "0.125": a multiple of 1/1000 as the file writes it.
std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", v);
    return buf;
}

// "0x" and the word in `bits` / 4 hex digits.
std::string hexWord(uint32_t w, int bits = 32) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%0*x", bits / 4, w);
    return buf;
}

// Stages whose texels the program reads as signed bump offsets (the texture of t(n) in
// texbem/texbeml t(m), t(n); in ps_1_4 the texld of stage n that fills bem's second source rn),
// and stages whose bump matrix it reads (texbem/texbeml t(m): stage m; bem r(m): stage m).
struct BumpStages {
    uint32_t signedTexels = 0;
    uint32_t matrices = 0;
};

BumpStages bumpStagesOf(const ps11::Program& program) {
    BumpStages b;
    for (const Instruction& in : program.instructions) {
        const Opcode op = in.opcode();
        if (op == Opcode::TexBem || op == Opcode::TexBemL || op == Opcode::Bem) {
            b.signedTexels |= 1u << in.src[op == Opcode::Bem ? 1 : 0].index;
            b.matrices |= 1u << in.dst.index;
        }
    }
    return b;
}

// The plain texture of caseForProgram: one level, 2..8 texels a side, an unsigned format (V8U8
// on bump stages half the time), point or linear, wrap/clamp/mirror/border.
std::string plainTextureSection(Dice& dice, int stage, bool signedTexels) {
    using ps11::TexFormat;
    static const std::vector<TexFormat> kUnsigned = {TexFormat::A8R8G8B8, TexFormat::X8R8G8B8, TexFormat::L8,
                                                     TexFormat::A8L8};
    const TexFormat format = signedTexels && dice.chance(50) ? TexFormat::V8U8 : dice.pick(kUnsigned);
    const int width = 1 << dice.range(1, 3), height = 1 << dice.range(1, 3);
    const int bits = ps11::formatBits(format);
    std::string out = "[texture " + std::to_string(stage) + "]\nsize " + std::to_string(width) + " " +
                      std::to_string(height) + "\nformat " + ps11::texFormatName(format) + "\nlevel 0\n";
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const uint32_t texel = bits == 32 ? dice.word() : dice.word() & ((1u << bits) - 1);
            out += (x ? " " : "") + hexWord(texel, bits);
        }
        out += "\n";
    }
    static const std::vector<std::string> kAddress = {"wrap", "clamp", "mirror", "border"};
    const std::string u = dice.pick(kAddress), v = dice.pick(kAddress);
    out += "\n[sampler " + std::to_string(stage) + "]\nfilter " + (dice.chance(50) ? "point" : "linear") +
           "\naddress " + u + " " + v + "\n";
    if (u == "border" || v == "border") out += "border " + hexWord(dice.word()) + "\n";
    return out + "\n";
}

// ---- the whole environment of randomCase: each feature drawn on its own, with a probability
// (percent) that keeps a mismatch attributable to few of them.
constexpr int kHardwarePercent = 35;         // [require] hardware: a class that runs the version
constexpr int kPrecisionPercent = 25;        // [require] precision: fx8, fx12, float or ideal
constexpr int kFloatTargetPercent = 35;      // A16B16G16R16F or A32B32G32R32F render target
constexpr int kX8TargetPercent = 15;         // X8R8G8B8 (of the 8-bit targets)
constexpr int kDepthPercent = 40;            // depth on (D24S8), a random clear, zfunc, zwrite
constexpr int kPerspectivePercent = 40;      // rhw varies across the vertices
constexpr int kExtraTrianglesPercent = 40;   // 1..3 overlapping triangles after the quad
constexpr int kWideCoordinatesPercent = 45;  // u, v over [-k, k + 1], k = 1, 2, 4 (minification)
constexpr int kBlendPercent = 35;            // alphablend on, random factors, op and blend factor
constexpr int kAlphaTestPercent = 30;        // alphatest on FUNC REF
constexpr int kFogPercent = 30;              // vertex fog (specular alpha) with a random colour
constexpr int kColorWritePercent = 25;       // a colour write mask other than rgba
constexpr int kVolumePercent = 30;           // a sampled stage's texture is a volume
constexpr int kMipPercent = 45;              // a mip chain (levels 0 = generated, 2D only; or 2..all given)

using ps11::TexFormat;
// The texture formats of one class, in ps11::kFormatRows' order.
std::vector<TexFormat> formatsOf(ps11::FormatClass cls) {
    std::vector<TexFormat> out;
    for (size_t i = 0; i < ps11::kTexFormatCount; ++i)
        if (ps11::kFormatRows[i].cls == cls) out.push_back(TexFormat(i));
    return out;
}
const std::vector<TexFormat> kUnsignedFormats = formatsOf(ps11::FormatClass::Unorm8);
const std::vector<TexFormat> kSignedFormats = formatsOf(ps11::FormatClass::Signed);
const std::vector<TexFormat> kFloatFormats = formatsOf(ps11::FormatClass::Float);

const std::vector<std::string> kCompareFuncs = {"never",   "less",     "equal",        "lessequal",
                                                "greater", "notequal", "greaterequal", "always"};
const std::vector<std::string> kBlends = {
    "zero",        "one",          "srccolor",        "invsrccolor", "srcalpha",
    "invsrcalpha", "destalpha",    "invdestalpha",    "destcolor",   "invdestcolor",
    "srcalphasat", "bothsrcalpha", "bothinvsrcalpha", "blendfactor", "invblendfactor"};
const std::vector<std::string> kBlendOps = {"add", "subtract", "revsubtract", "min", "max"};

// A texture side: a power of two up to 2^maxLog2, or now and then one that is not.
int textureSide(Dice& dice, int maxLog2) {
    if (dice.chance(15)) {
        static const std::vector<int> kOther = {3, 5, 6, 7, 12};
        const int side = dice.pick(kOther);
        if (side <= 1 << maxLog2) return side;
    }
    return 1 << dice.range(0, maxLog2);
}

int levelSide(int side, int level) { return std::max(1, side >> level); }

int chainLength(int w, int h, int d) {
    int levels = 1;
    while (std::max({w, h, d}) >> levels) ++levels;
    return levels;
}

// One component of a float texel: mostly around [0, 1], sometimes far out, sometimes a value
// with a story (signed zero, the largest half, a tiny one).
std::string floatComponent(Dice& dice) {
    const int roll = dice.below(100);
    if (roll < 80) return number(dice.thousandths(-1.5, 2.5));
    if (roll < 95) return number(dice.thousandths(-40, 40));
    static const std::vector<std::string> kSpecial = {"0", "-0", "1", "-1", "0.5", "0.001", "-0.001", "1000", "65504"};
    return dice.pick(kSpecial);
}

std::string texelText(Dice& dice, TexFormat format) {
    if (!ps11::isFloatFormat(format)) {
        const int bits = ps11::formatBits(format);
        const uint32_t w = dice.word();
        return hexWord(bits == 32 ? w : w & ((1u << bits) - 1), bits);
    }
    const int count = format == TexFormat::R32F ? 1 : dice.chance(10) ? dice.range(1, 3) : 4;
    std::string out = "(";
    for (int c = 0; c < count; ++c) out += (c ? " " : "") + floatComponent(dice);
    return out + ")";
}

// `level K`, then its rows (height × depth of them, slice after slice) or a fill.
void appendLevel(std::string& out, Dice& dice, TexFormat format, int level, int w, int h, int d) {
    out += "level " + std::to_string(level) + "\n";
    if (level > 0 && dice.chance(20)) {
        out += "fill " + texelText(dice, format) + "\n";
        return;
    }
    for (int row = 0; row < h * d; ++row) {
        for (int x = 0; x < w; ++x) out += (x ? " " : "") + texelText(dice, format);
        out += "\n";
    }
}

// The [texture N] and [sampler N] of a sampled stage in randomCase: any format (signed ones
// more often on bump stages), 2D or volume, one level or a chain, min/mag/mip filters and
// every address mode.
std::string fullTextureSection(Dice& dice, int stage, bool signedTexels) {
    const int roll = dice.below(100);
    const int signedPercent = signedTexels ? 55 : 15, floatPercent = signedTexels ? 15 : 20;
    const TexFormat format = roll < signedPercent                  ? dice.pick(kSignedFormats)
                             : roll < signedPercent + floatPercent ? dice.pick(kFloatFormats)
                                                                   : dice.pick(kUnsignedFormats);
    const bool volume = dice.chance(kVolumePercent);
    const int width = textureSide(dice, volume ? 3 : 4), height = textureSide(dice, volume ? 3 : 4);
    const int depth = volume ? std::max(2, textureSide(dice, 3)) : 1;
    const int chain = chainLength(width, height, depth);
    int levels = 1;  // 0 = generated from level 0
    if (chain > 1 && dice.chance(kMipPercent)) levels = !volume && dice.chance(35) ? 0 : dice.range(2, chain);
    std::string out = "[texture " + std::to_string(stage) + "]\nsize " + std::to_string(width) + " " +
                      std::to_string(height) + (volume ? " " + std::to_string(depth) : std::string()) + "\nformat " +
                      ps11::texFormatName(format) + "\n";
    if (levels != 1) out += "levels " + std::to_string(levels) + "\n";
    for (int k = 0; k < std::max(1, levels); ++k)
        appendLevel(out, dice, format, k, levelSide(width, k), levelSide(height, k), volume ? levelSide(depth, k) : 1);

    static const std::vector<std::string> kFilters = {"point", "linear"};
    const std::string minFilter = dice.pick(kFilters), magFilter = dice.pick(kFilters);
    std::string mip = "none";
    if (levels != 1) {
        const int m = dice.below(100);
        mip = m < 20 ? "none" : m < 60 ? "point" : "linear";
    } else if (dice.chance(15)) {
        mip = dice.pick(kFilters);  // a mip filter over a single level
    }
    out += "\n[sampler " + std::to_string(stage) + "]\nfilter " + minFilter;
    if (magFilter != minFilter) out += " " + magFilter;
    if (mip != "none") out += " mip " + mip;
    static const std::vector<std::string> kAddress = {"wrap", "clamp", "mirror", "border", "mirroronce"};
    std::vector<std::string> modes = {dice.pick(kAddress), dice.pick(kAddress)};
    if (volume) modes.push_back(dice.pick(kAddress));
    out += "\naddress";
    for (const std::string& m : modes) out += " " + m;
    out += "\n";
    if (std::find(modes.begin(), modes.end(), "border") != modes.end()) out += "border " + hexWord(dice.word()) + "\n";
    return out + "\n";
}

// How randomCase draws beyond the program (all off for caseForProgram).
struct Environment {
    bool full = false;
    bool depth = false;
    bool perspective = false;
    int extraTriangles = 0;
    double coordinateLo = -0.5, coordinateHi = 1.5;  // u and v of the vertices
};

// One vertex line of `draw triangles xyzrhw` at (x, y): z (random with a depth buffer), rhw
// (random with perspective), diffuse, specular (its alpha is the fog factor) and every texture
// set of the version with four components; the third and fourth (the divisors of _dz and _dw)
// stay in [0.25, 1.5], away from zero.
std::string vertexLine(Dice& dice, const Environment& env, int minor, double x, double y) {
    std::string v = number(x) + " " + number(y);
    if (env.full)
        v += " " + number(env.depth ? dice.thousandths(0, 1) : 0) + " " +
             number(env.perspective ? dice.thousandths(0.1, 2) : 1) + " ";
    else
        v += " 0 1 ";
    v += hexWord(dice.word()) + " " + hexWord(dice.word());
    for (int t = 0; t < ps11::registerCount(RegType::Texture, minor); ++t) {
        v += " t" + std::to_string(t);
        for (int c = 0; c < 4; ++c)
            v += " " +
                 number(c < 2 ? dice.thousandths(env.coordinateLo, env.coordinateHi) : dice.thousandths(0.25, 1.5));
    }
    return v;
}

// The [render state] lines of randomCase (empty when it draws none of them).
std::string renderStateSection(Dice& dice, bool depth) {
    std::string out;
    if (dice.chance(kBlendPercent)) {
        const std::string src = dice.pick(kBlends), dst = dice.pick(kBlends);
        out += "alphablend on\nsrcblend " + src + "\ndestblend " + dst + "\n";
        if (!dice.chance(50)) out += "blendop " + dice.pick(kBlendOps) + "\n";
        if (src.find("blendfactor") != std::string::npos || dst.find("blendfactor") != std::string::npos ||
            dice.chance(20))
            out += "blendfactor " + hexWord(dice.word()) + "\n";
    }
    if (dice.chance(kAlphaTestPercent))
        out += "alphatest on " + dice.pick(kCompareFuncs) + " " + std::to_string(dice.below(256)) + "\n";
    if (dice.chance(kFogPercent)) out += "fog on " + hexWord(dice.word()) + "\n";
    if (depth) {
        // Mostly the functions that keep some pixels and reject others.
        static const std::vector<std::string> kUsual = {"less", "lessequal", "greater", "greaterequal"};
        out += "zfunc " + (dice.chance(70) ? dice.pick(kUsual) : dice.pick(kCompareFuncs)) + "\n";
        if (dice.chance(30)) out += "zwrite off\n";
    }
    if (dice.chance(kColorWritePercent)) {
        const int mask = dice.below(15);  // any but rgba
        std::string letters;
        for (int c = 0; c < 4; ++c)
            if (mask & (1 << c)) letters += "rgba"[c];
        out += "colorwrite " + (letters.empty() ? std::string("none") : letters) + "\n";
    }
    return out.empty() ? out : "[render state]\n" + out + "\n";
}

// Everything but the shader: the file around `shader`, whose [pixel shader] block comes last
// before [test]. `full` draws randomCase's whole environment; otherwise caseForProgram's plain
// one (the same text, draw for draw, as before the environment existed).
std::string testTextOf(Dice& dice, const ps11::Program& program, const std::string& shader, int width, int height,
                       bool full) {
    const int minor = program.version.minor;
    std::string out = "% a random ps_1_" + std::to_string(minor) +
                      " case (runner/random_program.cpp): one draw, no probes\n[require]\nversion ps_1_" +
                      std::to_string(minor) + "\n";
    Environment env;
    env.full = full;
    if (full) {
        if (dice.chance(kHardwarePercent)) {
            std::vector<std::string> classes;
            for (const ps11::HardwareClass& h : ps11::hardwareClasses())
                if (h.maxMinor >= minor) classes.emplace_back(h.name);
            out += "hardware " + dice.pick(classes) + "\n";
        }
        if (dice.chance(kPrecisionPercent)) {
            static const std::vector<std::string> kPrecisions = {"fx8", "fx12", "float", "ideal"};
            out += "precision " + dice.pick(kPrecisions) + "\n";
        }
    }
    out += "\n[render target]\nsize " + std::to_string(width) + " " + std::to_string(height) + "\n";
    if (full) {
        if (dice.chance(kFloatTargetPercent))
            out += dice.chance(50) ? "format A16B16G16R16F\n" : "format A32B32G32R32F\n";
        else if (dice.chance(kX8TargetPercent))
            out += "format X8R8G8B8\n";
    }
    out += "clear " + hexWord(dice.word()) + "\n";
    if (full && dice.chance(kDepthPercent)) {
        env.depth = true;
        out += "depth on " + (dice.chance(30) ? std::string("1") : number(dice.thousandths(0, 1))) + "\n";
    }
    out += "\n";
    const uint32_t sampled = ps11::sampledStages(program);
    const BumpStages bump = bumpStagesOf(program);
    for (int stage = 0; stage < 8; ++stage)
        if (sampled & (1u << stage)) {
            const bool signedTexels = bump.signedTexels & (1u << stage);
            out +=
                full ? fullTextureSection(dice, stage, signedTexels) : plainTextureSection(dice, stage, signedTexels);
        }
    for (int stage = 0; stage < 8; ++stage) {
        if (!(bump.matrices & (1u << stage))) continue;
        out += "[stage " + std::to_string(stage) + "]\nbumpenvmat";
        for (int k = 0; k < 4; ++k) out += " " + number(dice.thousandths(-1, 1));
        out +=
            "\nlscale " + number(dice.thousandths(0, 2)) + "\nloffset " + number(dice.thousandths(-0.5, 0.5)) + "\n\n";
    }
    if (full) {
        out += renderStateSection(dice, env.depth);
        env.perspective = dice.chance(kPerspectivePercent);
        if (dice.chance(kExtraTrianglesPercent)) env.extraTriangles = dice.range(1, 3);
        if (dice.chance(kWideCoordinatesPercent)) {
            static const std::vector<int> kSpans = {1, 2, 4};
            const int k = dice.pick(kSpans);
            env.coordinateLo = -k, env.coordinateHi = k + 1;
        }
    }
    out += "[constants]\n";
    for (int c = 0; c < ps11::registerCount(RegType::Const, minor); ++c) {
        out += "c" + std::to_string(c);
        for (int k = 0; k < 4; ++k) out += " " + number(dice.thousandths(-1, 1));
        out += "\n";
    }
    out += "\n[pixel shader]\n" + shader + "\n\n[test]\ndraw triangles xyzrhw\n";
    // The quad's corners sit half a pixel outside the target (the 1:1 mapping of `draw quad`),
    // two triangles 0 1 2 and 0 2 3. u and v range over [-0.5, 1.5] (or wider) so wrap, mirror,
    // clamp and border all show.
    const double lo = -0.5, hx = width - 0.5, hy = height - 0.5;
    const std::array<std::array<double, 2>, 4> corners = {{{lo, lo}, {hx, lo}, {hx, hy}, {lo, hy}}};
    std::array<std::string, 4> vertices;
    for (size_t k = 0; k < 4; ++k) vertices[k] = vertexLine(dice, env, minor, corners[k][0], corners[k][1]);
    for (size_t k : {0, 1, 2, 0, 2, 3}) out += vertices[k] + "\n";
    // Triangles over the quad, partly outside the target: their edges cut quads, they overlap
    // each other, and they meet the depth test, blending and the write mask over pixels the
    // quad has just written.
    for (int t = 0; t < env.extraTriangles; ++t)
        for (int k = 0; k < 3; ++k)
            out += vertexLine(dice, env, minor, dice.thousandths(-0.25 * width, 1.25 * width),
                              dice.thousandths(-0.25 * height, 1.25 * height)) +
                   "\n";
    return out;
}

// ---------------------------------------------------------------- shrinking the environment

std::vector<std::string> splitLines(const std::string& text) {
    std::vector<std::string> lines;
    size_t begin = 0;
    while (begin < text.size()) {
        const size_t end = text.find('\n', begin);
        lines.push_back(text.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
        if (end == std::string::npos) break;
        begin = end + 1;
    }
    return lines;
}

std::string joinLines(const std::vector<std::string>& lines) {
    std::string text;
    for (const std::string& line : lines) text += line + "\n";
    return text;
}

std::vector<std::string> wordsOf(const std::string& line) {
    std::vector<std::string> words;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const size_t begin = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > begin) words.push_back(line.substr(begin, i - begin));
    }
    return words;
}

bool parsesAsTestFile(const std::string& text) {
    ps11::TestFile file;
    std::vector<ps11::TestFileError> errors;
    return ps11::parseTestFile(text, "shrink.ps11test", file, errors);
}

// Simpler versions of a case file's environment (never its shader), the boldest first: a whole
// section left out (every one but [require], [render target], [pixel shader] and [test]); an
// extra triangle of the draw left out; one keyword line left out ([require] version and the
// target's size stay); a texture down to its level 0; the vertices at rhw 1, then at z 0. Some
// do not parse (a sampler's filter line is fine to drop, a texture's format line is not): the
// caller checks.
std::vector<std::string> simplerEnvironments(const std::string& text) {
    const std::vector<std::string> lines = splitLines(text);
    struct Section {
        std::string name;   // "texture 0", "render state", ...
        size_t begin, end;  // the section line, one past its last line
    };
    std::vector<Section> sections;
    for (size_t i = 0; i < lines.size(); ++i) {
        if (!lines[i].starts_with("[")) continue;
        if (!sections.empty()) sections.back().end = i;
        const size_t close = lines[i].find(']');
        sections.push_back(
            {lines[i].substr(1, close == std::string::npos ? std::string::npos : close - 1), i, lines.size()});
    }
    std::vector<std::string> out;
    auto without = [&](size_t begin, size_t end) {
        std::vector<std::string> kept(lines.begin(), lines.begin() + long(begin));
        kept.insert(kept.end(), lines.begin() + long(end), lines.end());
        out.push_back(joinLines(kept));
    };
    auto isShaderOrTest = [](const std::string& name) { return name.starts_with("pixel shader") || name == "test"; };
    for (const Section& s : sections)
        if (s.name != "require" && s.name != "render target" && !isShaderOrTest(s.name)) without(s.begin, s.end);
    // The draw's vertex lines: 6 for the quad, then the extra triangles, 3 lines each.
    std::vector<size_t> vertexLines;
    for (const Section& s : sections)
        if (s.name == "test")
            for (size_t i = s.begin + 1; i < s.end; ++i)
                if (!lines[i].empty() && (lines[i][0] == '-' || (lines[i][0] >= '0' && lines[i][0] <= '9')))
                    vertexLines.push_back(i);
    for (size_t v = 6; v + 3 <= vertexLines.size() && vertexLines[v] + 2 == vertexLines[v + 2]; v += 3)
        without(vertexLines[v], vertexLines[v] + 3);
    for (const Section& s : sections) {
        if (isShaderOrTest(s.name) || s.name.starts_with("texture")) continue;
        for (size_t i = s.begin + 1; i < s.end; ++i) {
            const std::vector<std::string> words = wordsOf(lines[i]);
            if (words.empty() || words[0].starts_with("%")) continue;
            if ((s.name == "require" && words[0] == "version") || (s.name == "render target" && words[0] == "size"))
                continue;
            without(i, i + 1);
        }
    }
    // A mip chain down to its level 0: the levels line and the levels after 0 go.
    for (const Section& s : sections) {
        if (!s.name.starts_with("texture")) continue;
        size_t levels = 0, level1 = 0;
        for (size_t i = s.begin + 1; i < s.end; ++i) {
            const std::vector<std::string> words = wordsOf(lines[i]);
            if (words.size() == 2 && words[0] == "levels") levels = i;
            if (words.size() == 2 && words[0] == "level" && words[1] != "0" && !level1) level1 = i;
        }
        if (!levels) continue;
        size_t end = s.end;
        while (end > s.begin && lines[end - 1].empty()) --end;  // the blank line after the section stays
        std::vector<std::string> kept;
        for (size_t i = 0; i < lines.size(); ++i)
            if (i != levels && !(level1 && i >= level1 && i < end)) kept.push_back(lines[i]);
        out.push_back(joinLines(kept));
    }
    // Every vertex at rhw 1 (no perspective), then at z 0.
    for (size_t word : {size_t(3), size_t(2)}) {
        const char* value = word == 3 ? "1" : "0";
        std::vector<std::string> changed = lines;
        bool any = false;
        for (size_t i : vertexLines) {
            std::vector<std::string> words = wordsOf(lines[i]);
            if (words.size() <= word || words[word] == value || words[word] == (word == 3 ? "1.000" : "0.000"))
                continue;
            words[word] = value;
            std::string line;
            for (const std::string& w : words) line += (line.empty() ? "" : " ") + w;
            changed[i] = line;
            any = true;
        }
        if (any) out.push_back(joinLines(changed));
    }
    return out;
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
