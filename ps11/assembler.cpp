// Assembler front end: lexer and parser for ps_1_1 … ps_1_4 text. Runs on the
// preprocessor's output lines, builds the IR with the source location of every
// instruction and operand, and reports syntax errors as P11xx. Version rules are the
// validator's job; this stage only rejects what cannot be encoded and registers the version
// does not have (as Microsoft's assembler does even with validation off).
#include "ps11/assembler.h"

#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "ps11/suggest.h"

namespace ps11 {
namespace {

// Syntax diagnostic codes (docs/diagnostics.md).
constexpr const char* kMissingVersion = "P1101";
constexpr const char* kBadVersion = "P1102";
constexpr const char* kUnknownMnemonic = "P1103";
constexpr const char* kBadModifier = "P1104";
constexpr const char* kOperandCount = "P1105";
constexpr const char* kBadRegister = "P1106";
constexpr const char* kBadMask = "P1107";
constexpr const char* kBadSwizzle = "P1108";
constexpr const char* kBadSrcModifier = "P1109";
constexpr const char* kBadNumber = "P1110";
constexpr const char* kUnexpected = "P1111";
constexpr const char* kDanglingCoissue = "P1112";
constexpr const char* kDuplicateVersion = "P1113";
constexpr const char* kNoSuchRegister = "P1114";

char lower(char c) { return char(std::tolower(static_cast<unsigned char>(c))); }
bool isIdentStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool isIdentChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool isDigit(char c) { return c >= '0' && c <= '9'; }

std::string toLower(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = lower(c);
    return out;
}

// Cursor over one preprocessed line.
class LineParser {
public:
    LineParser(const PreprocessedLine& line, Diagnostics& diags) : m_line(line), m_text(line.text), m_diags(diags) {
        // ';' starts a comment (Microsoft's assembler); '//' too, in case the
        // preprocessor left one (it normally strips them).
        size_t end = m_text.size();
        for (size_t i = 0; i < m_text.size(); ++i) {
            if (m_text[i] == ';' || (m_text[i] == '/' && i + 1 < m_text.size() && m_text[i + 1] == '/')) {
                end = i;
                break;
            }
        }
        m_text = m_text.substr(0, end);
    }

    SourceLoc loc() const { return m_line.locAt(m_pos); }
    SourceLoc locAt(size_t pos) const { return m_line.locAt(pos); }
    size_t pos() const { return m_pos; }
    void skipSpace() {
        while (m_pos < m_text.size() && std::isspace(static_cast<unsigned char>(m_text[m_pos]))) ++m_pos;
    }
    bool atEnd() {
        skipSpace();
        return m_pos >= m_text.size();
    }
    char peek() {
        skipSpace();
        return m_pos < m_text.size() ? m_text[m_pos] : '\0';
    }
    char peekRaw() const { return m_pos < m_text.size() ? m_text[m_pos] : '\0'; }
    char peekRaw(size_t ahead) const { return m_pos + ahead < m_text.size() ? m_text[m_pos + ahead] : '\0'; }
    bool accept(char c) {
        if (peek() != c) return false;
        ++m_pos;
        return true;
    }
    // An identifier made of letters, digits and '_' (no dots).
    std::string_view identifier() {
        skipSpace();
        size_t start = m_pos;
        if (m_pos < m_text.size() && isIdentStart(m_text[m_pos])) {
            ++m_pos;
            while (m_pos < m_text.size() && isIdentChar(m_text[m_pos])) ++m_pos;
        }
        return m_text.substr(start, m_pos - start);
    }
    std::string_view rest() {
        skipSpace();
        return m_text.substr(m_pos);
    }
    // Trims a trailing '+' (the "+ at the end of the line" co-issue style) and reports it.
    bool takeTrailingPlus() {
        size_t end = m_text.size();
        while (end > m_pos && std::isspace(static_cast<unsigned char>(m_text[end - 1]))) --end;
        if (end > m_pos && m_text[end - 1] == '+') {
            // Not the exponent sign of a float literal ("1e+"): that would be malformed anyway.
            m_text = m_text.substr(0, end - 1);
            return true;
        }
        return false;
    }
    std::string_view text() const { return m_text; }
    void advance(size_t n) { m_pos += n; }
    void setPos(size_t p) { m_pos = p; }

    void error(const char* code, SourceLoc at, std::string msg) { m_diags.error(code, at, std::move(msg)); }

private:
    const PreprocessedLine& m_line;
    std::string_view m_text;
    Diagnostics& m_diags;
    size_t m_pos = 0;
};

// Parses "ps_1_1", "ps.1.1", "PS_1_4" at the start of the line. Returns true if the line
// is a version statement (valid or not).
// `minorOut` is set to the version's minor number when the statement is a valid first version.
bool parseVersion(LineParser& p, Program& prog, bool& seen, int& minorOut) {
    std::string_view t = p.text();
    size_t start = 0;
    while (start < t.size() && std::isspace(static_cast<unsigned char>(t[start]))) ++start;
    if (t.size() - start < 2 || lower(t[start]) != 'p' || lower(t[start + 1]) != 's') return false;
    size_t i = start + 2;
    if (i >= t.size() || (t[i] != '_' && t[i] != '.')) return false;
    // From here on it is a version statement.
    size_t end = i;
    while (end < t.size() && !std::isspace(static_cast<unsigned char>(t[end]))) ++end;
    std::string_view word = t.substr(start, end - start);
    SourceLoc at = p.locAt(start);
    p.setPos(end);
    int major = -1, minor = -1;
    char sep = t[i];
    if (word.size() == 6 && word[4] == sep && isDigit(word[3]) && isDigit(word[5])) {
        major = word[3] - '0';
        minor = word[5] - '0';
    }
    if (major < 0) {
        p.error(kBadVersion, at, "malformed version " + quote(word) + "; expected ps_1_1 … ps_1_4 or ps.1.1 … ps.1.4");
    } else if (major != 1 || minor < 1 || minor > 4) {
        p.error(kBadVersion, at,
                "unsupported shader version " + quote(word) + "; ps11 handles ps_1_1, ps_1_2, ps_1_3 and ps_1_4");
    } else if (seen) {
        p.error(kDuplicateVersion, at, "second version statement " + quote(word));
    } else {
        prog.version = {major, minor};
        prog.versionLoc = at;
        minorOut = minor;
    }
    seen = true;
    if (!p.atEnd()) p.error(kUnexpected, p.loc(), "unexpected text after the version: " + quote(p.rest()));
    return true;
}

// Parses a register name at the cursor: r#, v#, c#, t#. With a known version (minor 1-4) a
// register the version does not have is reported (P1114) but parsing goes on.
bool parseRegister(LineParser& p, RegType& type, uint8_t& index, int minor) {
    p.skipSpace();
    SourceLoc at = p.loc();
    char c = lower(p.peekRaw());
    switch (c) {
        case 'r': type = RegType::Temp; break;
        case 'v': type = RegType::Input; break;
        case 'c': type = RegType::Const; break;
        case 't': type = RegType::Texture; break;
        default: {
            std::string_view word = p.identifier();
            if (word.empty()) {
                char got = p.peekRaw();
                p.error(kBadRegister, at,
                        got ? "expected a register (r#, v#, c#, t#), found " + quote(std::string_view(&got, 1))
                            : "expected a register (r#, v#, c#, t#) at the end of the line");
            } else {
                p.error(kBadRegister, at, quote(word) + " is not a ps 1.x register (r#, v#, c#, t#)");
            }
            return false;
        }
    }
    if (!isDigit(p.peekRaw(1))) {
        std::string_view word = p.identifier();
        p.error(kBadRegister, at, quote(word) + " is not a ps 1.x register (r#, v#, c#, t#)");
        return false;
    }
    p.advance(1);
    unsigned value = 0;
    size_t digits = 0;
    while (isDigit(p.peekRaw())) {
        value = value * 10 + unsigned(p.peekRaw() - '0');
        if (value > 255) value = 256;
        p.advance(1);
        ++digits;
    }
    if (isIdentStart(p.peekRaw()) && p.peekRaw() != '_') {
        p.error(kBadRegister, at, "malformed register name");
        return false;
    }
    if (value > 255) {
        p.error(kBadRegister, at, "register index too large");
        return false;
    }
    index = uint8_t(value);
    (void)digits;
    // Microsoft's assembler refuses these even with D3DCOMPILE_SKIP_VALIDATION (Wine's
    // d3dcompiler tests/asm.c failure_test: "mov r5, r0" and "tex t5" in ps_1_3; its asmparser.c
    // checks every source and destination register against the version's register counts).
    if (minor >= 1 && minor <= 4 && index >= registerCount(type, minor))
        p.error(kNoSuchRegister, at,
                "register '" + std::string(regPrefix(type)) + std::to_string(index) + "' does not exist in ps_1_" +
                    std::to_string(minor) + " (" + registerRange(type, minor) + ")");
    return true;
}

// Component letter → index (rgba or xyzw set).
int componentIndex(char c, int& set) {
    switch (lower(c)) {
        case 'r': set |= 1; return 0;
        case 'g': set |= 1; return 1;
        case 'b': set |= 1; return 2;
        case 'a': set |= 1; return 3;
        case 'x': set |= 2; return 0;
        case 'y': set |= 2; return 1;
        case 'z': set |= 2; return 2;
        case 'w': set |= 2; return 3;
        default: return -1;
    }
}

// Reads the letters after a '.'.
std::string_view letters(LineParser& p) {
    size_t start = p.pos();
    while (std::isalpha(static_cast<unsigned char>(p.peekRaw()))) p.advance(1);
    return p.text().substr(start, p.pos() - start);
}

bool parseWriteMask(LineParser& p, uint8_t& mask) {
    SourceLoc at = p.loc();
    std::string_view word = letters(p);
    if (word.empty() || word.size() > 4) {
        p.error(kBadMask, at,
                "write mask " + quote("." + std::string(word)) + " must be 1 to 4 of r, g, b, a (or x, y, z, w)");
        return false;
    }
    int set = 0, last = -1;
    mask = 0;
    for (char c : word) {
        int comp = componentIndex(c, set);
        if (comp < 0) {
            p.error(kBadMask, at, "write mask '." + std::string(word) + "' has '" + std::string(1, c) +
                                       "', not a component (r, g, b, a or x, y, z, w)");
            return false;
        }
        if (comp <= last) {
            p.error(kBadMask, at, "write mask '." + std::string(word) +
                                       "' must list components once each in r, g, b, a order");
            return false;
        }
        last = comp;
        mask |= uint8_t(1u << comp);
    }
    if (set == 3) {
        p.error(kBadMask, at, "write mask '." + std::string(word) + "' mixes rgba and xyzw letters");
        return false;
    }
    return true;
}

bool parseSwizzle(LineParser& p, uint8_t& swizzle) {
    SourceLoc at = p.loc();
    std::string_view word = letters(p);
    if (word.empty() || word.size() > 4) {
        p.error(kBadSwizzle, at,
                "source selector " + quote("." + std::string(word)) + " must be 1 to 4 component letters");
        return false;
    }
    int set = 0;
    int comps[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < word.size(); ++i) {
        comps[i] = componentIndex(word[i], set);
        if (comps[i] < 0) {
            p.error(kBadSwizzle, at, "source selector '." + std::string(word) + "' has '" + std::string(1, word[i]) +
                                         "', not a component (r, g, b, a or x, y, z, w)");
            return false;
        }
    }
    if (set == 3) {
        p.error(kBadSwizzle, at, "source selector '." + std::string(word) + "' mixes rgba and xyzw letters");
        return false;
    }
    // A partial selector repeats its last letter (.xy = .xyyy).
    for (size_t i = word.size(); i < 4; ++i) comps[i] = comps[word.size() - 1];
    swizzle = uint8_t(comps[0] | (comps[1] << 2) | (comps[2] << 4) | (comps[3] << 6));
    return true;
}

// Parses a source suffix modifier after '_' (bias, bx2, x2, dz, db, dw, da).
bool parseSuffixModifier(LineParser& p, std::string& suffix) {
    SourceLoc at = p.loc();
    p.advance(1);  // '_'
    size_t start = p.pos();
    while (std::isalnum(static_cast<unsigned char>(p.peekRaw()))) p.advance(1);
    suffix = toLower(p.text().substr(start, p.pos() - start));
    if (suffix == "bias" || suffix == "bx2" || suffix == "x2" || suffix == "dz" || suffix == "db" || suffix == "dw" ||
        suffix == "da")
        return true;
    p.error(kBadSrcModifier, at,
            "unknown source modifier " + quote("_" + suffix) + " (known: _bias, _bx2, _x2, _dz/_db, _dw/_da)");
    return false;
}

bool parseSource(LineParser& p, Src& src, int minor) {
    p.skipSpace();
    src.loc = p.loc();
    bool negate = false, complement = false;
    if (p.accept('-')) negate = true;
    // "1-r0" / "1 - r0": complement.
    p.skipSpace();
    if (p.peekRaw() == '1') {
        size_t save = p.pos();
        p.advance(1);
        if (p.accept('-')) {
            complement = true;
        } else {
            p.setPos(save);
        }
    }
    if (!parseRegister(p, src.type, src.index, minor)) return false;
    std::string suffix;
    bool haveSwizzle = false;
    // Accept the modifier suffix before or after the selector (r0_bx2.a and r0.a_bx2).
    for (int round = 0; round < 2; ++round) {
        if (p.peekRaw() == '_' && suffix.empty()) {
            if (!parseSuffixModifier(p, suffix)) return false;
        } else if (p.peekRaw() == '.' && !haveSwizzle) {
            p.advance(1);
            if (!parseSwizzle(p, src.swizzle)) return false;
            haveSwizzle = true;
        }
    }
    if (p.peekRaw() == '_' || p.peekRaw() == '.') {
        p.error(kBadSrcModifier, p.loc(), "more than one source modifier or selector");
        return false;
    }
    if (complement && (negate || !suffix.empty())) {
        p.error(kBadSrcModifier, src.loc, "the invert modifier '1-' combines with no other source modifier");
        return false;
    }
    if (complement) {
        src.mod = SrcMod::Comp;
    } else if (suffix.empty()) {
        src.mod = negate ? SrcMod::Neg : SrcMod::None;
    } else if (suffix == "bias") {
        src.mod = negate ? SrcMod::BiasNeg : SrcMod::Bias;
    } else if (suffix == "bx2") {
        src.mod = negate ? SrcMod::SignNeg : SrcMod::Sign;
    } else if (suffix == "x2") {
        src.mod = negate ? SrcMod::X2Neg : SrcMod::X2;
    } else {
        if (negate) {
            p.error(kBadSrcModifier, src.loc, "'-' cannot be combined with _" + suffix);
            return false;
        }
        src.mod = (suffix == "dz" || suffix == "db") ? SrcMod::Dz : SrcMod::Dw;
    }
    return true;
}

bool parseDest(LineParser& p, Dst& dst, int minor) {
    p.skipSpace();
    dst.loc = p.loc();
    if (p.peekRaw() == '-' || p.peekRaw() == '1') {
        p.error(kBadRegister, dst.loc, "a destination register takes no source modifier");
        return false;
    }
    if (!parseRegister(p, dst.type, dst.index, minor)) return false;
    if (p.peekRaw() == '.') {
        p.advance(1);
        if (!parseWriteMask(p, dst.mask)) return false;
    } else if (p.peekRaw() == '_') {
        p.error(kBadModifier, p.loc(), "instruction modifiers belong on the mnemonic (mov_sat r0, …), not the register");
        return false;
    }
    return true;
}

// A float literal for def: [-+]digits[.digits][e[-+]digits][f], leading-dot allowed,
// or bits(0x7fc00000) for an exact bit pattern (printed by the disassembler for NaN/inf).
bool parseFloat(LineParser& p, uint32_t& bits) {
    p.skipSpace();
    SourceLoc at = p.loc();
    std::string_view t = p.text().substr(p.pos());
    if (t.size() >= 5 && toLower(t.substr(0, 5)) == "bits(") {
        size_t close = t.find(')');
        std::string inner(close == std::string_view::npos ? t.substr(5) : t.substr(5, close - 5));
        const char* b = inner.c_str();
        if (inner.size() > 2 && inner[0] == '0' && lower(inner[1]) == 'x') b += 2;
        unsigned long long v = 0;
        auto [ptr, ec] = std::from_chars(b, inner.c_str() + inner.size(), v, 16);
        if (close == std::string_view::npos || ec != std::errc() || ptr != inner.c_str() + inner.size() ||
            v > 0xFFFFFFFFull) {
            p.error(kBadNumber, at, "malformed bits(0x…) literal; expected up to 8 hex digits");
            return false;
        }
        bits = uint32_t(v);
        p.advance(close + 1);
        return true;
    }
    size_t i = 0;
    std::string num;
    if (i < t.size() && (t[i] == '-' || t[i] == '+')) num += t[i++];
    size_t mantStart = i;
    bool digits = false;
    while (i < t.size() && isDigit(t[i])) num += t[i++], digits = true;
    if (i < t.size() && t[i] == '.') {
        num += t[i++];
        while (i < t.size() && isDigit(t[i])) num += t[i++], digits = true;
    }
    if (digits && i < t.size() && lower(t[i]) == 'e') {
        size_t j = i + 1;
        std::string exp = "e";
        if (j < t.size() && (t[j] == '-' || t[j] == '+')) exp += t[j++];
        if (j < t.size() && isDigit(t[j])) {
            while (j < t.size() && isDigit(t[j])) exp += t[j++];
            num += exp;
            i = j;
        }
    }
    if (digits && i < t.size() && (lower(t[i]) == 'f' || lower(t[i]) == 'h')) ++i;
    if (!digits || (i < t.size() && (isIdentChar(t[i]) || t[i] == '.'))) {
        size_t end = i;
        while (end < t.size() && t[end] != ',' && !std::isspace(static_cast<unsigned char>(t[end]))) ++end;
        p.error(kBadNumber, at, quote(t.substr(0, std::max(end, mantStart + 1))) + " is not a number");
        return false;
    }
    // strtof rounds correctly to the nearest float; overflow gives ±inf like the C runtime.
    float f = std::strtof(num.c_str(), nullptr);
    bits = std::bit_cast<uint32_t>(f);
    p.advance(i);
    return true;
}

// "; did you mean 'mul'?" for an unknown mnemonic: the nearest one of the version (minor 1-4)
// when one is close, else the nearest of any version. Names come from the opcode table.
std::string suggestMnemonic(std::string_view word, int minor) {
    std::vector<std::string_view> ofVersion, any;
    for (const OpcodeInfo& row : opcodeTable()) {
        if (row.versions == 0) continue;  // reserved (texm3x3diff): never a suggestion
        any.push_back(row.mnemonic);
        if (row.versions & versionBit(minor)) ofVersion.push_back(row.mnemonic);
    }
    std::string s = didYouMean(word, ofVersion);
    return s.empty() ? didYouMean(word, any) : s;
}

// Splits "mov_x2_sat" into the mnemonic and its instruction modifiers. `minor` is the
// version's minor number, 0 when there is no valid version.
bool parseMnemonic(LineParser& p, const Program& prog, int minor, Instruction& inst) {
    p.skipSpace();
    SourceLoc at = p.loc();
    inst.loc = at;
    std::string_view word = p.identifier();
    if (word.empty()) {
        char c = p.peekRaw();
        p.error(kUnexpected, at, "expected an instruction, found " + quote(std::string_view(&c, 1)));
        return false;
    }
    std::string lw = toLower(word);
    // The mnemonic is the longest prefix before a '_' that names an opcode.
    size_t cut = lw.find('_');
    std::string mnemonic = lw.substr(0, cut);
    inst.info = findOpcode(mnemonic, prog.version.minor);
    if (!inst.info) {
        p.error(kUnknownMnemonic, at,
                "unknown instruction " + quote(word.substr(0, cut)) + suggestMnemonic(mnemonic, minor));
        return false;
    }
    bool haveShift = false;
    while (cut != std::string::npos) {
        size_t next = lw.find('_', cut + 1);
        std::string mod = lw.substr(cut + 1, next == std::string::npos ? std::string::npos : next - cut - 1);
        SourceLoc modAt = p.locAt(p.pos() - word.size() + cut);
        int8_t shift = 0;
        if (mod == "sat") {
            if (inst.dst.saturate) {
                p.error(kBadModifier, modAt, "_sat given twice");
                return false;
            }
            inst.dst.saturate = true;
        } else if (mod == "x2") {
            shift = 1;
        } else if (mod == "x4") {
            shift = 2;
        } else if (mod == "x8") {
            shift = 3;
        } else if (mod == "d2") {
            shift = -1;
        } else if (mod == "d4") {
            shift = -2;
        } else if (mod == "d8") {
            shift = -3;
        } else {
            p.error(
                kBadModifier, modAt,
                "unknown instruction modifier " + quote("_" + mod) + " (known: _x2, _x4, _x8, _d2, _d4, _d8, _sat)");
            return false;
        }
        if (shift != 0) {
            if (haveShift) {
                p.error(kBadModifier, modAt, "only one shift modifier (_x2, _x4, _x8, _d2, _d4, _d8) per instruction");
                return false;
            }
            haveShift = true;
            inst.dst.shift = shift;
        }
        cut = next;
    }
    if ((haveShift || inst.dst.saturate) && !inst.info->hasDst) {
        p.error(kBadModifier, at, "'" + std::string(inst.info->mnemonic) + "' takes no instruction modifier");
        return false;
    }
    return true;
}

bool expectComma(LineParser& p, const Instruction& inst, int have) {
    if (p.accept(',')) return true;
    int want = (inst.info->hasDst ? 1 : 0) + inst.info->numSrc + (inst.opcode() == Opcode::Def ? 4 : 0);
    SourceLoc at = p.loc();
    if (p.atEnd()) {
        p.error(kOperandCount, at,
                "'" + std::string(inst.info->mnemonic) + "' takes " + std::to_string(want) + " operands, found " +
                    std::to_string(have));
    } else {
        p.error(kUnexpected, at, "expected ',' before " + quote(p.rest()));
    }
    return false;
}

bool parseOperands(LineParser& p, int minor, Instruction& inst) {
    const OpcodeInfo& info = *inst.info;
    int have = 0;
    int want = (info.hasDst ? 1 : 0) + info.numSrc + (info.opcode == Opcode::Def ? 4 : 0);
    if (info.hasDst) {
        if (p.atEnd()) {
            p.error(kOperandCount, p.loc(),
                    "'" + std::string(info.mnemonic) + "' takes " + std::to_string(want) + " operand" +
                        (want == 1 ? "" : "s") + ", found 0");
            return false;
        }
        if (!parseDest(p, inst.dst, minor)) return false;
        ++have;
    }
    if (info.opcode == Opcode::Def) {
        for (int i = 0; i < 4; ++i) {
            if (!expectComma(p, inst, have)) return false;
            if (!parseFloat(p, inst.defBits[size_t(i)])) return false;
            ++have;
        }
    }
    for (int i = 0; i < info.numSrc; ++i) {
        if (!expectComma(p, inst, have)) return false;
        if (!parseSource(p, inst.src[size_t(i)], minor)) return false;
        ++have;
    }
    if (!p.atEnd()) {
        SourceLoc at = p.loc();
        if (p.peek() == ',') {
            int extra = have;
            while (p.accept(',')) {
                ++extra;
                while (!p.atEnd() && p.peek() != ',') p.advance(1);
            }
            p.error(kOperandCount, at,
                    "'" + std::string(info.mnemonic) + "' takes " + std::to_string(want) + " operand" +
                        (want == 1 ? "" : "s") + ", found " + std::to_string(extra));
        } else {
            p.error(kUnexpected, at, "unexpected " + quote(p.rest()) + " after the operands");
        }
        return false;
    }
    return true;
}

}  // namespace

std::optional<Program> parseAssembly(std::string_view text, const std::string& fileName,
                                     const AssembleOptions& options, Diagnostics& diags) {
    size_t errorsBefore = diags.errorCount();
    std::vector<PreprocessedLine> lines = preprocess(text, fileName, options.preprocess, diags);
    Program prog;
    bool seenVersion = false;
    int minor = 0;                // the version's minor number once a valid version statement was read
    bool pendingCoissue = false;  // a line ended with '+'
    SourceLoc pendingAt;
    for (const PreprocessedLine& line : lines) {
        LineParser p(line, diags);
        if (p.atEnd()) continue;
        if (!seenVersion || (p.peek() == 'p' || p.peek() == 'P')) {
            if (parseVersion(p, prog, seenVersion, minor)) continue;
        }
        if (!seenVersion) {
            p.error(kMissingVersion, p.loc(), "the shader must start with a version statement (ps_1_1 … ps_1_4)");
            seenVersion = true;  // report once; parse the rest as ps_1_1
        }
        Instruction inst;
        bool coissue = false;
        if (p.accept('+')) coissue = true;
        bool trailing = p.takeTrailingPlus();
        if (p.atEnd()) {
            if (coissue || trailing) pendingCoissue = true, pendingAt = p.loc();
            continue;
        }
        if (pendingCoissue) {
            coissue = true;
            pendingCoissue = false;
        }
        inst.coissue = coissue;
        if (!parseMnemonic(p, prog, minor, inst)) continue;
        if (!parseOperands(p, minor, inst)) continue;
        prog.instructions.push_back(inst);
        if (trailing) {
            pendingCoissue = true;
            pendingAt = inst.loc;
        }
    }
    if (pendingCoissue)
        diags.error(kDanglingCoissue, pendingAt, "'+' (co-issue) is not followed by an instruction");
    if (!seenVersion) {
        SourceLoc at;
        at.fileId = diags.addFile(fileName);
        at.line = 1;
        at.col = 1;
        diags.error(kMissingVersion, at, "empty shader: expected a version statement (ps_1_1 … ps_1_4)");
    }
    if (diags.errorCount() > errorsBefore) return std::nullopt;
    return prog;
}

}  // namespace ps11
