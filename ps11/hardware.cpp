// Hardware classes: the table of emulated GPUs and the resolution of a run's class, profile
// and MaxValue. Each row's facts and their public sources are in docs/precision.md
// ("Hardware classes"); this table is the only place that states them in code.
#include "ps11/hardware.h"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <vector>

#include "ps11/diagnostics.h"
#include "ps11/suggest.h"

namespace ps11 {

namespace {

// MaxValue of the D3D9-class rows: float registers keep values far past ±1 between instructions
// (Wine's cnd_test relies on a 2.0); the caps value such drivers report is not public, so the
// bound is the largest half-float, beyond what ps_1_x programs reach from [−1, 1] inputs short
// of long _x4 chains (docs/precision.md).
constexpr float kD3D9MaxValue = 65504.0f;

constexpr std::array<HardwareClass, 5> kClasses{{
    {"geforce4", "1.1-class", "NVIDIA GeForce4 Ti (NV25), register combiners", 3, Precision::Fx8, 1.0f,
     SignedDecode::Snorm, CoissuedCnd::Parallel, 8},
    {"geforce3", "1.1-class", "NVIDIA GeForce3 (NV20), register combiners", 1, Precision::Fx8, 1.0f,
     SignedDecode::Snorm, CoissuedCnd::Parallel, 8},
    {"radeon8500", "1.4-class", "ATI Radeon 8500/9000/9100/9200 (R200 family)", 4, Precision::Fx12, 8.0f,
     SignedDecode::Unclamped, CoissuedCnd::Parallel, 8},
    {"d3d9", "D3D9-class", "Direct3D 9 GPUs running ps_1_x as Wine's visual tests expect (AMD)", 4,
     Precision::Float, kD3D9MaxValue, SignedDecode::Asymmetric, CoissuedCnd::Parallel, 8},
    {"geforce7", "D3D9-class", "NVIDIA GeForce 6/7 and later running ps_1_x", 4, Precision::Float, kD3D9MaxValue,
     SignedDecode::Widen8, CoissuedCnd::Sequential, 8},
}};

bool iequal(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
            return false;
    return true;
}

std::string number(float v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", double(v));
    return b;
}

}  // namespace

std::span<const HardwareClass> hardwareClasses() { return kClasses; }

int hardwareIndex(const HardwareClass& h) { return int(&h - kClasses.data()); }

const HardwareClass* findHardware(std::string_view name) {
    for (const HardwareClass& h : kClasses)
        if (iequal(h.name, name)) return &h;
    return nullptr;
}

const HardwareClass& defaultHardware(int minor) { return minor >= 4 ? kClasses[2] : kClasses[0]; }

std::string hardwareNames() {
    std::string s;
    for (const HardwareClass& h : kClasses) {
        if (!s.empty()) s += ", ";
        s += h.name;
    }
    return s;
}

std::string unknownHardwareMessage(std::string_view name) {
    std::vector<std::string_view> names;
    for (const HardwareClass& h : kClasses) names.push_back(h.name);
    return "unknown hardware class " + quote(name) + " (expected " + hardwareNames() + ")" + didYouMean(name, names);
}

const char* signedDecodeName(SignedDecode d) {
    switch (d) {
        case SignedDecode::Snorm:
            return "snorm";
        case SignedDecode::Unclamped:
            return "unclamped";
        case SignedDecode::Asymmetric:
            return "asymmetric";
        case SignedDecode::Widen8:
            return "widen8";
    }
    return "?";
}

SignedValue decodeSignedChannel(SignedDecode mode, int32_t s, int bits) {
    const int64_t top = int64_t(1) << (bits - 1);  // 2^(n−1)
    switch (mode) {
        case SignedDecode::Snorm:
            return {s < -(top - 1) ? -(top - 1) : s, top - 1};
        case SignedDecode::Unclamped:
            return {s, top - 1};
        case SignedDecode::Asymmetric:
            return {s, s < 0 ? top : top - 1};
        case SignedDecode::Widen8: {
            if (bits >= 8) return decodeSignedChannel(SignedDecode::Snorm, s, bits);
            // The n-bit pattern repeated until it fills a byte (5 bits abcde -> abcdeabc), read
            // as a signed byte.
            const uint32_t u = uint32_t(s) & ((1u << bits) - 1);
            uint32_t wide = 0;
            int filled = 0;
            for (; filled < 8; filled += bits) wide = (wide << bits) | u;
            wide >>= filled - 8;
            const int32_t s8 = int32_t(wide & 0xff) - ((wide & 0x80) ? 256 : 0);
            return decodeSignedChannel(SignedDecode::Snorm, s8, 8);
        }
    }
    return {s, top - 1};
}

std::string HardwareConfig::describe() const {
    std::string s = std::string(hardware->name) + " (" + std::string(hardware->kind) + "), " + precisionName(precision);
    if (precisionOverridden) s += " (override)";
    s += ", max value " + number(maxValue);
    if (maxValueOverridden) s += " (override)";
    if (maxValueCapped) s += " (the class's, capped by " + std::string(precisionName(precision)) + ")";
    return s;
}

HardwareConfig resolveHardware(const HardwareClass* hardware, int minor, std::optional<Precision> precision,
                               float maxValue) {
    HardwareConfig c;
    c.hardware = hardware ? hardware : &defaultHardware(minor);
    c.precision = precision.value_or(c.hardware->precision);
    c.precisionOverridden = precision.has_value() && *precision != c.hardware->precision;
    c.weightBits = c.precisionOverridden ? (isFixedPoint(c.precision) ? 8 : 0) : c.hardware->bilinearWeightBits;
    c.maxValue = maxValue > 0 ? maxValue : c.hardware->maxValue;
    c.maxValueOverridden = maxValue > 0 && maxValue != c.hardware->maxValue;
    if (!(maxValue > 0) && double(c.maxValue) > maxRepresentableValue(c.precision)) {
        c.maxValue = float(std::floor(maxRepresentableValue(c.precision)));
        c.maxValueCapped = true;
    }
    return c;
}

}  // namespace ps11
