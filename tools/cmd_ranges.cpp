// `ps11 check --ranges` (tools/cmd_ranges.h): parses the inputs' ranges, runs the range proof
// (ps11/range_proof.h) and prints it as a table or as JSON (docs/intervals.md "The range proof").
#include "tools/cmd_ranges.h"

#include <cmath>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "ps11/disassembler.h"
#include "tools/cli_util.h"

namespace ps11 {
namespace {

// "--texN-range" style names: prefix, digit, suffix; returns N or -1.
int indexedOption(const std::string& a, const std::string& prefix, const std::string& suffix, int count) {
    if (a.size() != prefix.size() + 1 + suffix.size() || a.compare(0, prefix.size(), prefix) != 0 ||
        a.compare(prefix.size() + 1, suffix.size(), suffix) != 0)
        return -1;
    const int n = a[prefix.size()] - '0';
    return n >= 0 && n < count ? n : -1;
}

std::string num(double v) {
    if (!std::isfinite(v)) return v > 0 ? "inf" : v < 0 ? "-inf" : "nan";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

std::string channels(uint8_t mask) {
    std::string s;
    for (int c = 0; c < 4; ++c)
        if ((mask >> c) & 1) s += componentLetter(c);
    return s;
}

nlohmann::ordered_json number(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); }

std::string inputsLine(const Program& program, const RangeProofSetup& s) {
    (void)program;
    std::string line;
    for (int t = 0; t < kMaxTextureStages; ++t) {
        const ValueRange& r = s.textures[size_t(t)];
        if (r.lo != 0 || r.hi != 1 || !s.filtered[size_t(t)])
            line += "; t" + std::to_string(t) + " in [" + num(r.lo) + ", " + num(r.hi) + "]" +
                    (s.filtered[size_t(t)] ? "" : " point-sampled");
    }
    return line;
}

}  // namespace

bool takeRangeOption(const std::vector<std::string>& args, size_t& i, RangeOptions& o, std::string& error) {
    const std::string& a = args[i];
    const int c = indexedOption(a, "--c", "", 8), texRange = indexedOption(a, "--tex", "-range", kMaxTextureStages),
              texPoint = indexedOption(a, "--tex", "-point", kMaxTextureStages),
              vRange = indexedOption(a, "--v", "-range", 2), tcRange = indexedOption(a, "--tc", "-range", kMaxTexCoordSets);
    if (texPoint >= 0) {
        o.setup.filtered[size_t(texPoint)] = false;
        return true;
    }
    if (a != "--hardware" && c < 0 && texRange < 0 && vRange < 0 && tcRange < 0) return false;
    if (i + 1 >= args.size()) {
        error = a + " needs a value";
        return true;
    }
    const std::string& v = args[++i];
    if (a == "--hardware") {
        o.hardware = findHardware(v);
        if (!o.hardware) error = unknownHardwareMessage(v);
    } else if (c >= 0) {
        std::optional<std::array<float, 4>> x = cli::parseVector(v, false);
        if (!x)
            error = "bad value for " + a + ": '" + v + "' (expected 1-4 comma-separated floats)";
        else
            o.setup.constants[size_t(c)] = *x;
    } else {
        std::optional<std::pair<float, float>> r = cli::parseRange(v);
        if (!r) {
            error = "bad value for " + a + ": '" + v + "' (expected lo,hi: two floats with lo <= hi)";
            return true;
        }
        const ValueRange vr = ValueRange::between(r->first, r->second, false);
        if (texRange >= 0) o.setup.textures[size_t(texRange)] = vr;
        if (vRange >= 0) o.setup.colors[size_t(vRange)] = vr;
        if (tcRange >= 0) o.setup.texcoords[size_t(tcRange)] = vr;
    }
    return true;
}

bool checkRanges(const Program& program, const std::string& path, const RangeOptions& options, bool json,
                 nlohmann::ordered_json* out) {
    const HardwareConfig hw = resolveHardware(options.hardware, program.version.minor, std::nullopt, 0);
    if (program.version.minor > hw.hardware->maxMinor) {
        std::cerr << "ps11: check: " << path << ": hardware " << hw.hardware->name << " runs ps_1_1 ... ps_1_"
                  << hw.hardware->maxMinor << "; this shader is ps_1_" << program.version.minor << "\n";
        return false;
    }
    RangeProofSetup setup = options.setup;
    setup.options = executorOptionsFor(hw);
    Diagnostics diags;
    std::optional<RangeProof> proof = proveRanges(program, setup, diags);
    std::cerr << diags.formatAll();
    if (!proof) return false;

    if (json) {
        nlohmann::ordered_json j;
        j["file"] = path;
        j["hardware"] = hw.hardware->name;
        j["precision"] = precisionName(setup.options.precision);
        j["max_value"] = proof->options.maxValue;
        nlohmann::ordered_json insts = nlohmann::ordered_json::array();
        for (const InstructionRange& r : proof->instructions) {
            nlohmann::ordered_json i;
            i["line"] = r.loc.line;
            i["text"] = r.text;
            if (r.step.writes) {
                i["dst"] = r.text.substr(r.text.find(' ') + 1, r.text.find(',') - r.text.find(' ') - 1);
                nlohmann::ordered_json lo = nlohmann::ordered_json::array(), hi = nlohmann::ordered_json::array();
                for (const ChannelInterval& ch : r.step.dst) {
                    lo.push_back(number(ch.bounded ? ch.lo : -INFINITY));
                    hi.push_back(number(ch.bounded ? ch.hi : INFINITY));
                }
                i["min"] = lo;
                i["max"] = hi;
                i["written"] = channels(r.step.mask);
            } else {
                i["dst"] = nullptr;
            }
            i["clamps"] = r.step.clamps != 0;
            i["saturates"] = r.step.saturates != 0;
            if (r.step.clamps) {
                i["clamped_channels"] = channels(r.step.clamps);
                nlohmann::ordered_json onsets = nlohmann::ordered_json::array();
                for (const ClampOnset& o : r.onsets)
                    onsets.push_back({{"input", o.input}, {o.above ? "above" : "below", o.value}});
                i["clamp_onsets"] = onsets;
            }
            if (r.step.saturates) i["saturated_channels"] = channels(r.step.saturates);
            insts.push_back(i);
        }
        j["instructions"] = insts;
        auto bound = [](const LevelBound& b) {
            nlohmann::ordered_json ch = nlohmann::ordered_json::array();
            for (double v : b.levels) ch.push_back(number(v));
            return std::make_pair(number(b.max()), ch);
        };
        const auto [fx8, fx8ch] = bound(proof->fx8);
        const auto [fx12, fx12ch] = bound(proof->fx12);
        j["outputs"]["r0"]["bound_levels"] = {{"fx8", fx8}, {"fx12", fx12}};
        j["outputs"]["r0"]["bound_levels_per_channel"] = {{"fx8", fx8ch}, {"fx12", fx12ch}};
        j["outputs"]["r0"]["texkill"] = proof->result.kill == KillRange::Never ? "never"
                                        : proof->result.kill == KillRange::Always ? "always"
                                                                                   : "maybe";
        const InstructionRange* first = proof->firstClamp();
        j["range_safe"] = first == nullptr;
        *out = j;
        return true;
    }

    std::cout << path << ": ranges on " << hw.describe() << "; inputs: textures, v# and coordinates in [0, 1]"
              << inputsLine(program, setup) << "; constants as defined or given\n";
    std::printf("  %-5s %-28s %-14s %-14s %-14s %-14s %s\n", "line", "instruction", "r", "g", "b", "a", "findings");
    for (const InstructionRange& r : proof->instructions) {
        std::string cells[4];
        for (int c = 0; c < 4; ++c) {
            const ChannelInterval& ch = r.step.dst[size_t(c)];
            if (!r.step.writes || !((r.step.mask >> c) & 1))
                cells[c] = "";
            else if (!ch.bounded)
                cells[c] = "unbounded";
            else
                cells[c] = ch.lo == ch.hi ? num(ch.lo) : "[" + num(ch.lo) + ", " + num(ch.hi) + "]";
        }
        std::string findings;
        if (r.step.clamps) {
            findings += "CLAMPS ." + channels(r.step.clamps) + " at ±" + num(proof->options.maxValue);
            for (const ClampOnset& o : r.onsets)
                findings += std::string(findings.back() == ';' ? " " : "; ") + "from " + o.input + (o.above ? " > " : " < ") +
                            num(o.value);
        }
        if (r.step.saturates) findings += std::string(findings.empty() ? "" : "; ") + "_sat cuts ." + channels(r.step.saturates);
        std::string text = r.text.size() > 28 ? r.text.substr(0, 27) + "~" : r.text;
        std::printf("  %-5u %-28s %-14s %-14s %-14s %-14s %s\n", r.loc.line, text.c_str(), cells[0].c_str(),
                    cells[1].c_str(), cells[2].c_str(), cells[3].c_str(), findings.c_str());
    }
    auto levels = [](const LevelBound& b) {
        if (!b.bounded) return std::string("unbounded (a dependent lookup or bem: its coordinates may differ)");
        std::string s;
        for (int c = 0; c < 4; ++c) s += std::string(c ? " " : "") + componentLetter(c) + " " + num(b.levels[size_t(c)]);
        return s;
    };
    std::cout << "r0 against the float profile at MaxValue " << num(proof->options.maxValue)
              << ", worst case in 8-bit levels:\n  fx8:  " << levels(proof->fx8) << "\n  fx12: " << levels(proof->fx12)
              << "\n";
    if (proof->result.kill == KillRange::Maybe)
        std::cout << "  (texkill may discard: the bound holds where both profiles keep the pixel)\n";
    const InstructionRange* first = proof->firstClamp();
    std::cout << (first ? "not range-safe: line " + std::to_string(first->loc.line) + " (" + first->text + ") clamps\n"
                        : std::string("range-safe: no register clamp acts\n"));
    return true;
}

}  // namespace ps11
