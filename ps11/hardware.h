// Hardware classes (docs/precision.md "Hardware classes"): which GPU a result stands for. A class
// is one documented bundle of the behaviours that make the same ps_1_x program give different
// colours on different cards: the highest ps_1_x version, the precision profile,
// PixelShader1xMaxValue, how signed (bump) texels decode, how a co-issued cnd reads r0.a, and
// the sub-texel weight precision of bilinear filtering. Every value cites its source in the docs.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "ps11/precision.h"

namespace ps11 {

// How an n-bit signed channel s (−2^(n−1) … 2^(n−1)−1) of a bump format becomes a value.
enum class SignedDecode : uint8_t {
    Snorm,       // s / (2^(n−1) − 1), the most negative code clamped to −1 (GL / D3D10 rule)
    Unclamped,   // s / (2^(n−1) − 1), −2^(n−1) kept below −1 (R200: −128 → −1.0079)
    Asymmetric,  // s ≥ 0: s / (2^(n−1) − 1); s < 0: s / 2^(n−1) (both ends exactly ±1)
    Widen8,      // n < 8: s widened to 8 bits by repeating its top bits, then Snorm; n ≥ 8: Snorm
};

// What a co-issued cnd (ps_1_1 … 1_3, `+cnd` paired with a write of r0.a) compares.
enum class CoissuedCnd : uint8_t {
    Parallel,    // the r0.a of before the pair (both members read before either writes)
    Sequential,  // the r0.a its partner has just written
};

struct HardwareClass {
    std::string_view name;     // what --hardware and [require] hardware take
    std::string_view kind;     // "1.1-class", "1.4-class", "D3D9-class"
    std::string_view gpus;     // the cards it stands for
    int maxMinor = 1;          // highest ps_1_x version the class runs (D3DCAPS9::PixelShaderVersion)
    Precision precision = Precision::Fx8;
    float maxValue = 1;        // D3DCAPS9::PixelShader1xMaxValue
    SignedDecode signedDecode = SignedDecode::Snorm;
    CoissuedCnd coissuedCnd = CoissuedCnd::Parallel;
    int bilinearWeightBits = 8;  // sub-texel weight bits of bilinear and mip filtering
};

// Every class, the default first.
std::span<const HardwareClass> hardwareClasses();
// The class's position in hardwareClasses() (condition masks).
int hardwareIndex(const HardwareClass& h);
// Case-insensitive lookup; null when there is no such class.
const HardwareClass* findHardware(std::string_view name);
// The class a run uses when none is named: the 1.1-class card, or for ps_1_4 (which it cannot
// run) the 1.4-class card.
const HardwareClass& defaultHardware(int minor);
// "geforce4, geforce3, radeon8500, d3d9, geforce7" for messages.
std::string hardwareNames();
// "unknown hardware class 'x' (expected geforce4, …); did you mean 'd3d9'?" for a name
// findHardware does not know (quoted and cut like every user text).
std::string unknownHardwareMessage(std::string_view name);
const char* signedDecodeName(SignedDecode d);

// The value of an n-bit signed channel s (2 ≤ n ≤ 16) as a rational num / den (den > 0), exact.
struct SignedValue {
    int64_t num = 0;
    int64_t den = 1;
};
SignedValue decodeSignedChannel(SignedDecode mode, int32_t s, int bits);

// What a run uses after the overrides (--precision, max_value) are applied to a class.
struct HardwareConfig {
    const HardwareClass* hardware = nullptr;  // never null once resolved
    Precision precision = Precision::Fx8;
    float maxValue = 1;
    // Sub-texel weight bits of bilinear and mip filtering in the float profile: the class's when
    // its own profile runs; a --precision override brings that profile's definition (fx: 8,
    // float and ideal: 0, float32 weights), so the override changes arithmetic and filtering
    // together and the float profile means the same on every class.
    int weightBits = 8;
    bool precisionOverridden = false;
    bool maxValueOverridden = false;
    bool maxValueCapped = false;  // the class's MaxValue is beyond what an overriding fx profile holds
    // "geforce4 (1.1-class), fx8, max value 1" (overrides marked).
    std::string describe() const;
};

// Resolves a class for a shader version: `hardware` null = defaultHardware(minor); `precision` /
// `maxValue` (0 = none) override the class's values. A class MaxValue an overriding fx profile
// cannot hold (d3d9's 65504 in fx12) is capped to the largest it holds (maxRepresentableValue).
HardwareConfig resolveHardware(const HardwareClass* hardware, int minor, std::optional<Precision> precision,
                               float maxValue);

}  // namespace ps11
