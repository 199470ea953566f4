// `ps11 info`: what this build and machine offer — version, default hardware class, the
// executor's kernels, and the OpenGL context the GL backend would use.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

// ps11 info [--gl osmesa|egl] [--json]. Exit 0 even without a GL context (the error is printed),
// unless --gl names a kind that fails: then 1.
int cmdInfo(const std::vector<std::string>& args);

}  // namespace ps11
