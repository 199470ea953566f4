// The validator stage, reports: ShaderStats as readable text and as JSON (`ps11 check`,
// `ps11 check --json`).
#include "ps11/validator_internal.h"

namespace ps11 {
namespace {

std::string jsonEscape(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        switch (c) {
            case '"':
                out += "\\\"";
                break;
            case '\\':
                out += "\\\\";
                break;
            case '\n':
                out += "\\n";
                break;
            case '\r':
                out += "\\r";
                break;
            case '\t':
                out += "\\t";
                break;
            default:
                if (c < 0x20) {
                    static const char* hex = "0123456789abcdef";
                    out += "\\u00";
                    out += hex[c >> 4];
                    out += hex[c & 15];
                } else {
                    out += char(c);
                }
        }
    }
    return out + "\"";
}

std::string intList(const std::vector<int>& v, const char* prefix, const char* sep) {
    std::string out;
    for (int x : v) out += (out.empty() ? "" : sep) + std::string(prefix) + std::to_string(x);
    return out;
}

std::string versionString(const Version& v) { return "ps_" + std::to_string(v.major) + "_" + std::to_string(v.minor); }

}  // namespace

std::string statsToText(const ShaderStats& s) {
    std::string out = "version: " + versionString(s.version) + (s.valid ? " (valid)" : " (invalid)") + "\n";
    const bool v14 = s.version.minor == 4;
    if (v14 && s.hasPhase) {
        for (size_t p = 0; p < 2; ++p)
            out += "phase " + std::to_string(p + 1) + ": texture " + std::to_string(s.phaseTexSlots[p]) + "/" +
                   std::to_string(s.texLimit) + ", arithmetic " + std::to_string(s.phaseArithSlots[p]) + "/" +
                   std::to_string(s.arithLimit) + "\n";
    } else {
        out += "texture slots: " + std::to_string(s.texSlots) + "/" + std::to_string(s.texLimit) + "\n";
        out += "arithmetic slots: " + std::to_string(s.arithSlots) + "/" + std::to_string(s.arithLimit) + "\n";
    }
    out += "constants read: " + (s.constantsRead.empty() ? std::string("none") : intList(s.constantsRead, "c", " ")) +
           "\n";
    out += "constants defined: " +
           (s.constantsDefined.empty() ? std::string("none") : intList(s.constantsDefined, "c", " ")) + "\n";
    out += "read ports per instruction (most used / limit):";
    for (size_t t = 0; t < 4; ++t)
        out += std::string(t ? ", " : " ") + regPrefix(RegType(t)) + "# " + std::to_string(s.maxReadPorts[t]) + "/" +
               std::to_string(s.readPortLimit[t]);
    out += "\nread ports per co-issued pair (most used / limit " + std::to_string(s.pairReadPortLimit) + "):";
    for (size_t t = 0; t < 4; ++t)
        out += std::string(t ? ", " : " ") + regPrefix(RegType(t)) + "# " + std::to_string(s.maxPairReadPorts[t]);
    out += "\n";
    if (s.dp4Count || s.cmpCount || s.bemCount)
        out += "dp4: " + std::to_string(s.dp4Count) + ", cmp: " + std::to_string(s.cmpCount) +
               ", bem: " + std::to_string(s.bemCount) + "\n";
    out += "slots:\n";
    for (const InstructionStats& row : s.table) {
        std::string line = "  ";
        line += row.loc.line ? std::to_string(row.loc.line) : std::to_string(row.instruction);
        while (line.size() < 7) line += ' ';
        if (v14) line += "p" + std::to_string(row.phase) + " ";
        line += "T" + std::to_string(row.texSlots) + " A" + std::to_string(row.arithSlots) + "  " + row.text;
        out += line + "\n";
    }
    return out;
}

std::string statsToJson(const ShaderStats& s) {
    std::string out = "{";
    out += "\"version\":" + jsonEscape(versionString(s.version));
    out += ",\"valid\":" + std::string(s.valid ? "true" : "false");
    out += ",\"texSlots\":" + std::to_string(s.texSlots) + ",\"texLimit\":" + std::to_string(s.texLimit);
    out += ",\"arithSlots\":" + std::to_string(s.arithSlots) + ",\"arithLimit\":" + std::to_string(s.arithLimit);
    out += ",\"limitsPerPhase\":" + std::string(s.version.minor == 4 ? "true" : "false");
    out += ",\"phases\":[";
    if (s.version.minor == 4) {
        for (size_t p = s.hasPhase ? 0 : 1; p < 2; ++p) {
            if (p == 1 && s.hasPhase) out += ",";
            out += "{\"phase\":" + std::to_string(p + 1) + ",\"texSlots\":" + std::to_string(s.phaseTexSlots[p]) +
                   ",\"arithSlots\":" + std::to_string(s.phaseArithSlots[p]) + "}";
        }
    }
    out += "]";
    out += ",\"counts\":{\"dp4\":" + std::to_string(s.dp4Count) + ",\"cmp\":" + std::to_string(s.cmpCount) +
           ",\"bem\":" + std::to_string(s.bemCount) + "}";
    out += ",\"constantsRead\":[" + intList(s.constantsRead, "", ",") + "]";
    out += ",\"constantsDefined\":[" + intList(s.constantsDefined, "", ",") + "]";
    out += ",\"readPorts\":{";
    for (size_t t = 0; t < 4; ++t) {
        if (t) out += ",";
        out += std::string("\"") + regPrefix(RegType(t)) + "\":{\"max\":" + std::to_string(s.maxReadPorts[t]) +
               ",\"limit\":" + std::to_string(s.readPortLimit[t]) +
               ",\"pairMax\":" + std::to_string(s.maxPairReadPorts[t]) + "}";
    }
    out += "},\"pairReadPortLimit\":" + std::to_string(s.pairReadPortLimit);
    out += ",\"instructions\":[";
    for (size_t i = 0; i < s.table.size(); ++i) {
        const InstructionStats& row = s.table[i];
        if (i) out += ",";
        out += "{\"index\":" + std::to_string(row.instruction) + ",\"line\":" + std::to_string(row.loc.line) +
               ",\"col\":" + std::to_string(row.loc.col) + ",\"phase\":" + std::to_string(row.phase) +
               ",\"texSlots\":" + std::to_string(row.texSlots) + ",\"arithSlots\":" + std::to_string(row.arithSlots) +
               ",\"coissue\":" + (row.coissue ? "true" : "false") + ",\"text\":" + jsonEscape(row.text) + "}";
    }
    out += "]}";
    return out;
}
}  // namespace ps11
