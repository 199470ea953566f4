// Precision profiles (docs/precision.md): how register values are represented and rounded.
// fx8 and fx12 keep integers on a grid of 1/255 or 1/4080; float and ideal keep float32.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace ps11 {

enum class Precision : uint8_t { Fx8, Fx12, Float, Ideal };

const char* precisionName(Precision p);                     // "fx8", "fx12", "float", "ideal"
std::optional<Precision> parsePrecision(std::string_view s);  // case-insensitive

constexpr bool isFixedPoint(Precision p) { return p == Precision::Fx8 || p == Precision::Fx12; }
// Grid scale G: a register value is n / G (fx profiles); 1 for float profiles.
constexpr int32_t gridScale(Precision p) { return p == Precision::Fx8 ? 255 : p == Precision::Fx12 ? 4080 : 1; }

// Largest round(M·G) an fx profile runs with: fx lanes are int32 with sources k = 4n + 2G, and
// round(M·G) <= 2^24 keeps every product of the general formula (dp4, lrp, _x8) inside int64.
constexpr double kMaxGridBound = 16777216.0;
// The largest MaxValue profile p can represent (fx: 2^24 / G; float profiles: no bound).
constexpr double maxRepresentableValue(Precision p) {
    return p == Precision::Fx8 || p == Precision::Fx12 ? kMaxGridBound / gridScale(p) : 3.4e38;
}

// round_half_even(num / den) for den > 0, exact in integers.
constexpr int64_t roundHalfEven(int64_t num, int64_t den) {
    int64_t q = num / den, r = num % den;
    if (r < 0) r += den, q -= 1;  // floor division
    int64_t twice = 2 * r;
    if (twice > den || (twice == den && (q & 1))) ++q;
    return q;
}

// round_half_even(v * G) for a double v (exact for float inputs: 24 + 13 bits < 53).
int32_t toGrid(double v, Precision p);

// round_half_even(x) for |x| < 2^51 in the default rounding mode, without a library call: adding
// and removing 1.5 * 2^52 leaves no fraction bits, so the addition itself rounds (what
// std::nearbyint does). Not folded: without -ffast-math the compiler keeps IEEE rounding.
constexpr double kRoundMagic = 6755399441055744.0;
inline double roundEvenSmall(double x) { return (x + kRoundMagic) - kRoundMagic; }

// The 8-bit value a float stores into an 8-bit target or surface (docs/precision.md "Outputs"):
// round_half_even(clamp(v, 0, 1) * 255), NaN stores 0 (x * 255 is exact in double).
inline uint8_t unorm8OfFloat(double v) {
    const double c = v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;
    return uint8_t(roundEvenSmall(c * 255.0));
}

}  // namespace ps11
