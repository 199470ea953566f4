// The toolchain's version, from the top-level CMakeLists.txt's project(ps11 VERSION x.y.z).
#pragma once

#include <string_view>

namespace ps11 {

// "0.1.0": what `ps11 --version` prints after "ps11 ".
std::string_view versionString();

}  // namespace ps11
