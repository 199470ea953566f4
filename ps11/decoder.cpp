// The decoder stage: a D3D9 ps_1_1 … ps_1_4 token stream → the IR (ps1x-spec.md §5).
// ps 1.x instruction tokens carry no length, so operand counts come from the opcode table.
// Every malformed token gives a P3xxx diagnostic with its index and hex value
// (codes in docs/diagnostics.md); nothing is read past the end of the stream.
#include "ps11/decoder.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <iterator>

#include "ps11/token_format.h"

namespace ps11 {
namespace {

// Decoding stops after this many errors; a corrupt stream would otherwise report every token.
constexpr size_t kMaxErrors = 32;

// Number of raw IEEE-754 words that follow def's destination token (§5.5).
constexpr size_t kDefWords = 4;

std::string hex32(uint32_t v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%08x", v);
    return buf;
}

// D3DSPR_* names of the register types that are not legal in ps 1.x (§5.4), for messages.
const char* regTypeName(unsigned type) {
    static constexpr const char* kNames[] = {
        "temp",   "input",    "const",  "texture",     "rastout",     "attrout",  "output",
        "constint", "colorout", "depthout", "sampler", "const2",    "const3",   "const4",
        "constbool", "loop",   "tempfloat16", "misctype", "label",   "predicate",
    };
    return type < std::size(kNames) ? kNames[type] : "unknown";
}

const char* resultModName(unsigned bit) {
    switch (bit) {
        case 0x2: return "partial precision";
        case 0x4: return "centroid";
        default: return "unknown";
    }
}

// One pass over one stream. Holds the stream, the diagnostics sink and the program built so far.
class Decoder {
public:
    Decoder(std::span<const uint32_t> tokens, uint32_t fileId, Diagnostics& diags)
        : m_tokens(tokens), m_fileId(fileId), m_diags(diags) {}

    std::optional<Program> run();

private:
    SourceLoc locAt(size_t index) const {
        SourceLoc loc;
        loc.fileId = m_fileId;
        loc.tokenIndex = int32_t(index);
        return loc;
    }
    size_t remainingAfter(size_t index) const { return m_tokens.size() - index - 1; }

    // Reports "what (0x%08x)[: detail]" at token index; false once the error budget is spent.
    bool error(const char* code, size_t index, const std::string& what, const std::string& detail = {});
    bool budgetLeft() const { return m_errors < kMaxErrors; }

    bool decodeVersion();
    // Decodes the item at m_pos (instruction, comment or end); false when decoding must stop.
    bool decodeItem();
    bool checkInstructionBits(uint32_t token, size_t index);
    // Register fields shared by destination and source; false if the token is unusable.
    bool decodeRegister(size_t index, const char* role, const OpcodeInfo& info, RegType& type, uint8_t& num);
    void decodeDst(size_t index, const OpcodeInfo& info, Dst& dst);
    void decodeSrc(size_t index, const OpcodeInfo& info, int which, Src& src);

    std::span<const uint32_t> m_tokens;
    uint32_t m_fileId;
    Diagnostics& m_diags;
    Program m_program;
    size_t m_pos = 0;
    size_t m_errors = 0;
    bool m_sawEnd = false;
};

bool Decoder::error(const char* code, size_t index, const std::string& what, const std::string& detail) {
    if (!budgetLeft()) return false;
    std::string msg = what;
    if (index < m_tokens.size()) msg += " (" + hex32(m_tokens[index]) + ")";
    if (!detail.empty()) msg += ": " + detail;
    m_diags.error(code, locAt(index), std::move(msg));
    ++m_errors;
    if (m_errors == kMaxErrors) m_diags.note(locAt(index), "too many errors; decoding stopped");
    return budgetLeft();
}

bool Decoder::decodeVersion() {
    if (m_tokens.empty()) {
        error("P3003", 0, "empty token stream", "expected a pixel shader version token 0xffff01mm");
        return false;
    }
    const uint32_t t = m_tokens[0];
    const uint32_t tag = t & tok::kTypeMask;
    const unsigned major = tok::versionMajor(t);
    const unsigned minor = tok::versionMinor(t);
    if (tag == tok::kPixelShaderTag && major == 1 && minor >= 1 && minor <= 4) {
        m_program.version = Version{int(major), int(minor)};
        m_program.versionLoc = locAt(0);
        return true;
    }
    if ((tag == tok::kPixelShaderTag || tag == tok::kVertexShaderTag) && major >= 1 && major <= 3) {
        const char* kind = tag == tok::kPixelShaderTag ? "ps" : "vs";
        error("P3017", 0, "unsupported shader version " + std::string(kind) + "_" + std::to_string(major) + "_" +
                              std::to_string(minor),
              "only pixel shaders ps_1_1 to ps_1_4 are supported");
        return false;
    }
    error("P3003", 0, "invalid version token", "expected a pixel shader version token 0xffff01mm");
    return false;
}

bool Decoder::checkInstructionBits(uint32_t t, size_t index) {
    std::string why;
    auto add = [&why](const char* reason) {
        if (!why.empty()) why += ", ";
        why += reason;
    };
    if (t & tok::kInstReservedMask) add("reserved bit 31/29 set");
    if (t & tok::kPredicatedBit) add("predicated bit 28 set (ps 2.0+ only)");
    if (t & tok::kInstLengthMask) add("instruction length bits 24-27 set (ps 2.0+ only)");
    if (t & tok::kOpcodeSpecificMask) add("opcode-specific bits 16-23 set (ps 2.0+ only)");
    if (why.empty()) return true;
    return error("P3005", index, "reserved bits in instruction token", why);
}

bool Decoder::decodeItem() {
    const size_t index = m_pos;
    const uint32_t t = m_tokens[index];
    const uint32_t op = t & tok::kOpcodeMask;

    if (op == uint32_t(Opcode::End)) {
        // Only exactly 0x0000ffff is an end token; extra bits are reported but the stream still ends here.
        if (t != tok::kEndToken) error("P3005", index, "reserved bits in end token", "expected 0x0000ffff");
        m_sawEnd = true;
        ++m_pos;
        return false;
    }

    if (op == tok::kCommentOpcode) {
        // Comment: bits 16-30 = payload length in tokens, bit 31 = 0; the payload is arbitrary (§5.5).
        if (t & ~(tok::kCommentLengthMask | tok::kOpcodeMask)) {
            if (!error("P3005", index, "reserved bit 31 set in comment token")) return false;
        }
        const size_t length = (t & tok::kCommentLengthMask) >> tok::kCommentLengthShift;
        if (length > remainingAfter(index)) {
            error("P3008", index, "comment of " + std::to_string(length) + " tokens runs past the end",
                  "only " + std::to_string(remainingAfter(index)) + " tokens follow");
            return false;
        }
        m_pos += 1 + length;
        return true;
    }

    const int minor = m_program.version.minor;
    if (!checkInstructionBits(t, index)) return false;

    const OpcodeInfo* info = findOpcodeToken(op, minor);
    if (info == nullptr || info->versions == 0) {
        char opText[16];
        std::snprintf(opText, sizeof opText, "0x%08x", op);
        std::string detail = info ? "reserved opcode " + std::string(info->mnemonic) + " is invalid in every version"
                                  : "not a ps_1_" + std::to_string(minor) + " opcode";
        error("P3004", index, std::string("unknown opcode ") + opText, detail);
        return false;  // without the opcode the operand count, and so the rest of the stream, is unknown
    }

    const size_t numSrc = std::min<size_t>(info->numSrc, 3);
    const size_t operands = (info->hasDst ? 1 : 0) + numSrc + (info->opcode == Opcode::Def ? kDefWords : 0);
    if (operands > remainingAfter(index)) {
        error("P3006", index, "truncated instruction '" + std::string(info->mnemonic) + "'",
              "needs " + std::to_string(operands) + " operand tokens, only " +
                  std::to_string(remainingAfter(index)) + " follow");
        return false;
    }

    Instruction inst;
    inst.info = info;
    inst.coissue = (t & tok::kCoissueBit) != 0;
    inst.loc = locAt(index);
    size_t next = index + 1;
    if (info->hasDst) decodeDst(next++, *info, inst.dst);
    for (size_t s = 0; s < numSrc; ++s) decodeSrc(next++, *info, int(s), inst.src[s]);
    if (info->opcode == Opcode::Def) {
        // def's payload is four raw IEEE-754 words, not parameter tokens (bit 31 may be clear).
        for (size_t k = 0; k < kDefWords; ++k) inst.defBits[k] = m_tokens[next++];
    }
    m_program.instructions.push_back(inst);
    m_pos = next;
    return budgetLeft();
}

bool Decoder::decodeRegister(size_t index, const char* role, const OpcodeInfo& info, RegType& type, uint8_t& num) {
    const uint32_t t = m_tokens[index];
    const std::string where = std::string(role) + " of '" + std::string(info.mnemonic) + "'";
    if (!(t & tok::kParamBit)) {
        // Usually a sign that the stream is out of step; the other fields would be noise.
        error("P3009", index, "parameter token without bit 31", where);
        return false;
    }
    bool ok = true;
    const unsigned rawType = tok::regType(t);
    if (rawType > tok::kTypeMaxLegal) {
        error("P3010", index, "bad register type " + std::to_string(rawType) + " (" + regTypeName(rawType) + ")",
              where + "; ps 1.x has only r, v, c, t");
        ok = false;
    }
    if (t & tok::kRelativeBit) {
        error("P3011", index, "relative addressing bit 13 set", where);
        ok = false;
    }
    if (t & tok::kParamReservedMask) {
        error("P3011", index, "reserved bits 14-15 set", where);
        ok = false;
    }
    const unsigned rawNum = tok::regNum(t);
    if (rawNum > 255) {
        error("P3012", index, "register number " + std::to_string(rawNum) + " out of range", where);
        ok = false;
    }
    type = RegType(rawType & tok::kTypeMaxLegal);
    num = uint8_t(rawNum & 0xFFu);
    return ok;
}

void Decoder::decodeDst(size_t index, const OpcodeInfo& info, Dst& dst) {
    dst.loc = locAt(index);
    if (!decodeRegister(index, "destination", info, dst.type, dst.index)) return;
    const uint32_t t = m_tokens[index];
    const std::string where = "destination of '" + std::string(info.mnemonic) + "'";
    dst.mask = uint8_t(tok::writeMask(t));
    if (dst.mask == 0) error("P3016", index, "empty write mask", where);
    const unsigned mod = tok::resultMod(t);
    dst.saturate = (mod & tok::kResultModSaturate) != 0;
    for (unsigned bit = 0x2; bit <= 0x8; bit <<= 1) {
        if (mod & bit)
            error("P3013", index, "result modifier " + std::string(resultModName(bit)) + " not allowed in ps 1.x",
                  where);
    }
    const int shift = tok::shiftScale(t);
    if (shift < -3 || shift > 3) {
        error("P3014", index, "shift scale " + std::to_string(shift) + " has no ps 1.x form", where);
    } else {
        dst.shift = int8_t(shift);
    }
}

void Decoder::decodeSrc(size_t index, const OpcodeInfo& info, int which, Src& src) {
    src.loc = locAt(index);
    const std::string role = "source " + std::to_string(which);
    if (!decodeRegister(index, role.c_str(), info, src.type, src.index)) return;
    const uint32_t t = m_tokens[index];
    src.swizzle = uint8_t(tok::swizzle(t));
    const unsigned mod = tok::srcMod(t);
    if (mod > unsigned(SrcMod::Dw)) {
        error("P3015", index, "bad source modifier " + std::to_string(mod),
              role + " of '" + std::string(info.mnemonic) + "'; ps 1.x has modifiers 0-10");
    } else {
        src.mod = SrcMod(mod);
    }
}

std::optional<Program> Decoder::run() {
    if (!decodeVersion()) return std::nullopt;
    m_pos = 1;
    bool stoppedEarly = false;
    while (m_pos < m_tokens.size()) {
        if (!decodeItem()) {
            stoppedEarly = !m_sawEnd;
            break;
        }
    }
    if (m_sawEnd && m_pos < m_tokens.size()) {
        m_diags.warning("P3018", locAt(m_pos),
                        std::to_string(m_tokens.size() - m_pos) + " token(s) after the end token ignored (" +
                            hex32(m_tokens[m_pos]) + ")");
    }
    if (!m_sawEnd && !stoppedEarly) {
        const size_t last = m_tokens.size() - 1;
        error("P3007", last, "missing end token 0x0000ffff", "the stream ends after this token");
    }
    if (m_errors > 0) return std::nullopt;
    return std::move(m_program);
}

// Hex text: one word, its position, and whether it parsed.
bool isHexSeparator(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',' || c == '\f' || c == '\v'; }

int hexDigit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// Parses one word ("0x0000ffff", "ffff0101"); false if it is not hex or does not fit 32 bits.
bool parseHexWord(std::string_view word, uint32_t& value) {
    if (word.size() > 2 && word[0] == '0' && (word[1] == 'x' || word[1] == 'X')) word.remove_prefix(2);
    if (word.empty()) return false;
    uint64_t v = 0;
    for (char c : word) {
        const int d = hexDigit(c);
        if (d < 0) return false;
        v = v * 16 + uint64_t(d);
        if (v > 0xFFFFFFFFull) return false;
    }
    value = uint32_t(v);
    return true;
}

}  // namespace

std::optional<Program> decode(std::span<const uint32_t> tokens, uint32_t fileId, Diagnostics& diags) {
    return Decoder(tokens, fileId, diags).run();
}

std::optional<std::vector<uint32_t>> tokensFromBinary(std::string_view bytes, uint32_t fileId, Diagnostics& diags) {
    if (bytes.size() % 4 != 0) {
        SourceLoc loc;
        loc.fileId = fileId;
        loc.tokenIndex = int32_t(std::min<size_t>(bytes.size() / 4, INT32_MAX));
        std::string tail;
        for (size_t i = bytes.size() / 4 * 4; i < bytes.size(); ++i) {
            char buf[8];
            std::snprintf(buf, sizeof buf, " %02x", unsigned(static_cast<unsigned char>(bytes[i])));
            tail += buf;
        }
        diags.error("P3001", loc,
                    "binary size " + std::to_string(bytes.size()) + " bytes is not a multiple of 4 (" +
                        std::to_string(bytes.size() % 4) + " trailing bytes:" + tail + ")");
        return std::nullopt;
    }
    std::vector<uint32_t> tokens(bytes.size() / 4);
    for (size_t i = 0; i < tokens.size(); ++i) {
        uint32_t v = 0;
        for (size_t b = 0; b < 4; ++b) v |= uint32_t(static_cast<unsigned char>(bytes[i * 4 + b])) << (8 * b);
        tokens[i] = v;
    }
    return tokens;
}

std::optional<std::vector<uint32_t>> tokensFromHex(std::string_view text, uint32_t fileId, Diagnostics& diags) {
    std::vector<uint32_t> tokens;
    size_t errors = 0;
    uint32_t line = 1;
    size_t lineStart = 0;
    size_t i = 0;
    auto skipToEol = [&] {
        while (i < text.size() && text[i] != '\n') ++i;
    };
    auto startsComment = [&](size_t at) {
        const char c = text[at];
        return c == ';' || c == '#' || (c == '/' && at + 1 < text.size() && text[at + 1] == '/');
    };
    while (i < text.size()) {
        const char c = text[i];
        if (c == '\n') {
            ++line;
            lineStart = ++i;
            continue;
        }
        if (isHexSeparator(c)) {
            ++i;
            continue;
        }
        if (startsComment(i)) {
            skipToEol();
            continue;
        }
        const size_t start = i;
        while (i < text.size() && !isHexSeparator(text[i]) && !startsComment(i)) ++i;
        const std::string_view word = text.substr(start, i - start);
        uint32_t value = 0;
        if (parseHexWord(word, value)) {
            tokens.push_back(value);
            continue;
        }
        SourceLoc loc;
        loc.fileId = fileId;
        loc.line = line;
        loc.col = uint32_t(std::min<size_t>(start - lineStart + 1, UINT32_MAX));
        diags.error("P3002", loc, "bad hex word " + quote(word) + " (expected up to 8 hex digits, optional 0x)");
        if (++errors == kMaxErrors) {
            diags.note(loc, "too many errors; reading stopped");
            break;
        }
    }
    if (errors > 0) return std::nullopt;
    return tokens;
}

}  // namespace ps11
