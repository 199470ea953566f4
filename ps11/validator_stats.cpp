// The validator stage, reports: ShaderStats as readable text and as JSON (`ps11 check`,
// `ps11 check --json`).
#include "ps11/json_internal.h"
#include "ps11/validator_internal.h"

namespace ps11 {
namespace {

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
    using json::Json;
    Json j;
    j["version"] = versionString(s.version);
    j["valid"] = s.valid;
    j["texSlots"] = s.texSlots;
    j["texLimit"] = s.texLimit;
    j["arithSlots"] = s.arithSlots;
    j["arithLimit"] = s.arithLimit;
    j["limitsPerPhase"] = s.version.minor == 4;
    Json phases = Json::array();
    if (s.version.minor == 4)
        for (size_t p = s.hasPhase ? 0 : 1; p < 2; ++p)
            phases.push_back(
                {{"phase", p + 1}, {"texSlots", s.phaseTexSlots[p]}, {"arithSlots", s.phaseArithSlots[p]}});
    j["phases"] = std::move(phases);
    j["counts"] = {{"dp4", s.dp4Count}, {"cmp", s.cmpCount}, {"bem", s.bemCount}};
    j["constantsRead"] = s.constantsRead;
    j["constantsDefined"] = s.constantsDefined;
    Json ports = Json::object();
    for (size_t t = 0; t < 4; ++t)
        ports[regPrefix(RegType(t))] = {
            {"max", s.maxReadPorts[t]}, {"limit", s.readPortLimit[t]}, {"pairMax", s.maxPairReadPorts[t]}};
    j["readPorts"] = std::move(ports);
    j["pairReadPortLimit"] = s.pairReadPortLimit;
    Json rows = Json::array();
    for (const InstructionStats& row : s.table)
        rows.push_back({{"index", row.instruction},
                        {"line", row.loc.line},
                        {"col", row.loc.col},
                        {"phase", row.phase},
                        {"texSlots", row.texSlots},
                        {"arithSlots", row.arithSlots},
                        {"coissue", row.coissue},
                        {"text", row.text}});
    j["instructions"] = std::move(rows);
    return json::dumpCompact(j);
}
}  // namespace ps11
