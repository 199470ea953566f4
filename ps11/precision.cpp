// Precision profiles: names and the conversion of real values to grid integers
// (docs/precision.md).
#include "ps11/precision.h"

#include <cctype>
#include <cmath>
#include <string>

namespace ps11 {

std::optional<Precision> parsePrecision(std::string_view s) {
    std::string l;
    for (char c : s) l += char(std::tolower(static_cast<unsigned char>(c)));
    if (l == "fx8") return Precision::Fx8;
    if (l == "fx12") return Precision::Fx12;
    if (l == "float") return Precision::Float;
    if (l == "ideal") return Precision::Ideal;
    return std::nullopt;
}

int32_t toGrid(double v, Precision p) {
    double x = v * double(gridScale(p));
    if (!(x == x)) return 0;  // NaN
    if (x > 2.0e9) return 2000000000;
    if (x < -2.0e9) return -2000000000;
    // nearbyint rounds half to even in the default rounding mode.
    return int32_t(std::nearbyint(x));
}

}  // namespace ps11
