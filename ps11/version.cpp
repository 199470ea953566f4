// The version string: CMake passes project(ps11 VERSION …) to this file alone as PS11_VERSION,
// so a new version rebuilds one file.
#include "ps11/version.h"

#ifndef PS11_VERSION
#error "PS11_VERSION is set by CMakeLists.txt (project VERSION)"
#endif

namespace ps11 {

std::string_view versionString() { return PS11_VERSION; }

}  // namespace ps11
