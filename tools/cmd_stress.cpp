// `ps11 stress [--json] [--size N] [--hardware H]`: runs glare/stress.h's suite and prints it as one
// table of pitfalls (name | predicted | measured | fix | with fix), the §6 metrics per technique
// and the robustness checks, or as JSON ({"items": [...], "metrics": [...], "robustness": [...]}).
// Exit 1 when a robustness check fails.
#include "tools/cmd_stress.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "glare/stress.h"
#include "ps11/hardware.h"
#include "tools/cli_util.h"

namespace ps11 {

namespace {

const char* kStressUsage = "usage: ps11 stress [--json] [--size N] [--hardware H]\n";

std::string number(double v) {
    if (std::isnan(v)) return "n/a";
    char buf[32];
    if (v != 0 && (std::fabs(v) < 0.01 || std::fabs(v) >= 1e5))
        std::snprintf(buf, sizeof buf, "%.3g", v);
    else if (v == std::nearbyint(v))
        std::snprintf(buf, sizeof buf, "%.0f", v);
    else
        std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

std::string text(const glare::StressValue& v) {
    if (v.empty()) return "-";
    std::string s;
    for (const auto& [k, x] : v) {
        if (!s.empty()) s += ", ";
        s += k.empty() ? number(x) : k + " " + number(x);
    }
    return s;
}

// NaN and infinities become null (nlohmann writes null for them).
nlohmann::json json(const glare::StressValue& v) {
    if (v.empty()) return nullptr;
    if (v.size() == 1 && v[0].first.empty()) return v[0].second;
    nlohmann::json o = nlohmann::json::object();
    for (const auto& [k, x] : v) o[k] = x;
    return o;
}

// A short form of the fix for the table (up to its first colon).
std::string shortFix(const std::string& fix) { return fix.substr(0, fix.find(':')); }

}  // namespace

int cmdStress(const std::vector<std::string>& args) {
    bool asJson = false;
    glare::StressOptions o;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--json") {
            asJson = true;
        } else if (a == "--size" && i + 1 < args.size()) {
            const std::string& v = args[++i];
            char* end = nullptr;
            const long n = std::strtol(v.c_str(), &end, 10);
            if (!end || *end || n < 64 || n > 1024 || n % 8) {
                std::cerr << "ps11: stress: --size takes a multiple of 8 from 64 to 1024, not " << quote(v) << "\n";
                return cli::kUsage;
            }
            o.size = uint32_t(n);
        } else if (a == "--hardware" && i + 1 < args.size()) {
            o.hardware = findHardware(args[++i]);
            if (!o.hardware) {
                std::cerr << "ps11: stress: " << unknownHardwareMessage(args[i]) << "\n";
                return cli::kUsage;
            }
        } else if (a == "-h" || a == "--help") {
            std::cout << kStressUsage;
            return cli::kOk;
        } else {
            std::cerr << "ps11: stress: " << cli::unknownOption(a, {"--json", "--size", "--hardware"}) << "\n"
                      << kStressUsage;
            return cli::kUsage;
        }
    }
    const auto start = std::chrono::steady_clock::now();
    glare::StressReport r;
    std::string error;
    if (!glare::runStress(o, r, error)) {
        std::cerr << "ps11: stress: " << error << "\n";
        return cli::kUserError;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    if (asJson) {
        nlohmann::json j;
        j["hardware"] = r.hardware;
        j["size"] = o.size;
        j["items"] = nlohmann::json::array();
        for (const glare::StressItem& it : r.items)
            j["items"].push_back({{"name", it.name},
                                  {"unit", it.unit},
                                  {"setup", it.setup},
                                  {"predicted", json(it.predicted)},
                                  {"measured", json(it.measured)},
                                  {"fix", it.fix},
                                  {"measured_with_fix", json(it.measuredWithFix)},
                                  {"note", it.note}});
        j["metrics"] = nlohmann::json::array();
        for (const glare::TechniqueMetrics& m : r.metrics)
            j["metrics"].push_back({{"technique", m.technique},
                                    {"size", m.size},
                                    {"stability_frames", m.stabilityFrames},
                                    {"stability_energy", m.stabilityEnergy},
                                    {"stability_peak", m.stabilityPeak},
                                    {"firefly_share", m.fireflyShare},
                                    {"firefly_area", m.fireflyArea},
                                    {"dc_gain", m.dcGain},
                                    {"impulse_gain", m.impulseGain},
                                    {"r50", m.r50},
                                    {"r90", m.r90},
                                    {"visibility_radius", m.visibilityRadius},
                                    {"anisotropy", m.anisotropy},
                                    {"band_levels", m.bandLevels},
                                    {"band_step", m.bandStep}});
        j["robustness"] = nlohmann::json::array();
        for (const glare::RobustnessCheck& c : r.robustness)
            j["robustness"].push_back({{"name", c.name}, {"pass", c.pass}, {"detail", c.detail}});
        j["seconds"] = seconds;
        std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
        return r.robust() ? cli::kOk : cli::kUserError;
    }

    std::printf("ps11 stress on %s: GLARE.md §7 pitfalls (predicted from the formula, measured on the card's ps_1_1 "
                "passes)\n\n",
                r.hardware.c_str());
    std::printf("%-20s | %-34s | %-34s | %-16s | %s\n", "name", "predicted", "measured", "fix", "with fix");
    std::printf("%s\n", std::string(140, '-').c_str());
    for (const glare::StressItem& it : r.items)
        std::printf("%-20s | %-34s | %-34s | %-16s | %s\n", it.name.c_str(), text(it.predicted).c_str(),
                    text(it.measured).c_str(), shortFix(it.fix).c_str(), text(it.measuredWithFix).c_str());
    std::printf("\nunits and setups:\n");
    for (const glare::StressItem& it : r.items)
        std::printf("  %s: %s; %s. Fix: %s.%s%s\n", it.name.c_str(), it.unit.c_str(), it.setup.c_str(), it.fix.c_str(),
                    it.note.empty() ? "" : " Note: ", it.note.c_str());

    std::printf("\nGLARE.md §6 metrics per technique (published settings, %ux%u, glare = output − scene, red channel)\n\n",
                o.size, o.size);
    std::printf("%-9s %7s %9s %9s %9s %8s %8s %8s %6s %6s %6s %7s %7s %6s\n", "technique", "frames", "stab.E", "stab.peak",
                "ff.share", "ff.area", "DC gain", "imp.gain", "r50", "r90", "r_vis", "aniso", "levels", "step");
    for (const glare::TechniqueMetrics& m : r.metrics)
        std::printf("%-9s %7d %9s %9s %9s %8d %8s %8s %6s %6s %6s %7s %7d %6d\n", m.technique.c_str(), m.stabilityFrames,
                    number(m.stabilityEnergy).c_str(), number(m.stabilityPeak).c_str(), number(m.fireflyShare).c_str(),
                    m.fireflyArea, number(m.dcGain).c_str(), number(m.impulseGain).c_str(), number(m.r50).c_str(),
                    number(m.r90).c_str(), number(m.visibilityRadius).c_str(), number(m.anisotropy).c_str(),
                    m.bandLevels, m.bandStep);

    std::printf("\nrobustness\n");
    for (const glare::RobustnessCheck& c : r.robustness)
        std::printf("  %-4s %-28s %s\n", c.pass ? "PASS" : "FAIL", c.name.c_str(), c.detail.c_str());
    std::printf("\n%.1f s\n", seconds);
    return r.robust() ? cli::kOk : cli::kUserError;
}

}  // namespace ps11
