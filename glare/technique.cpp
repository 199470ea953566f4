#include "glare/technique.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace glare {

// Each technique's file defines its instance.
const Technique& adaptiveTechnique();
const Technique& glowTechnique();
const Technique& pyramidTechnique();
const Technique& quarterTechnique();
const Technique& spritesTechnique();

const std::vector<const Technique*>& techniques() {
    static const std::vector<const Technique*> all = {&adaptiveTechnique(), &glowTechnique(), &pyramidTechnique(),
                                                      &quarterTechnique(), &spritesTechnique()};
    return all;
}

const Technique* findTechnique(std::string_view name) {
    for (const Technique* t : techniques())
        if (t->name() == name) return t;
    return nullptr;
}

std::string unknownTechniqueMessage(std::string_view name) {
    std::string names;
    for (const Technique* t : techniques()) names += (names.empty() ? "" : ", ") + std::string(t->name());
    return "unknown technique '" + std::string(name) + "' (techniques: " + names + ")";
}

std::optional<Settings> presetSettings(const Technique& t, std::string_view preset) {
    for (size_t i = 0; i < kPresetNames.size(); ++i)
        if (kPresetNames[i] == preset) {
            Settings s;
            for (const ParamInfo& p : t.params()) s[p.name] = p.presets[i];
            return s;
        }
    return std::nullopt;
}

std::string settingText(const ParamInfo& p, double value) {
    if (!p.choices.empty()) {
        const size_t i = size_t(value);
        return i < p.choices.size() ? p.choices[i] : "?";
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", value);
    return buf;
}

bool applySetting(const Technique& t, Settings& settings, std::string_view assignment, std::string& error) {
    const size_t eq = assignment.find('=');
    if (eq == std::string_view::npos || eq == 0) {
        error = "--set takes name=value, not '" + std::string(assignment) + "'";
        return false;
    }
    const std::string name(assignment.substr(0, eq));
    const std::string value(assignment.substr(eq + 1));
    const ParamInfo* param = nullptr;
    for (const ParamInfo& p : t.params())
        if (p.name == name) param = &p;
    if (!param) {
        std::string names;
        for (const ParamInfo& p : t.params()) names += (names.empty() ? "" : ", ") + p.name;
        error = "technique " + std::string(t.name()) + " has no setting '" + name + "' (settings: " + names + ")";
        return false;
    }
    if (!param->choices.empty()) {
        for (size_t i = 0; i < param->choices.size(); ++i)
            if (param->choices[i] == value) {
                settings[name] = double(i);
                return true;
            }
        std::string names;
        for (const std::string& c : param->choices) names += (names.empty() ? "" : ", ") + c;
        error = "setting " + name + ": '" + value + "' is not one of " + names;
        return false;
    }
    double v = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (ec != std::errc() || end != value.data() + value.size() || !std::isfinite(v)) {
        error = "setting " + name + ": '" + value + "' is not a number";
        return false;
    }
    if (v < param->min || v > param->max || (param->integer && v != std::floor(v))) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "setting %s: %s is outside %s%g .. %g%s%s", name.c_str(), value.c_str(),
                      param->integer ? "the whole numbers " : "", param->min, param->max,
                      param->unit.empty() ? "" : " ", param->unit.c_str());
        error = buf;
        return false;
    }
    settings[name] = v;
    return true;
}

}  // namespace glare
