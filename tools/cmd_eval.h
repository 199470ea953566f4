// `ps11 eval`: runs a pixel shader for one pixel with interpolants, constants and 1×1 textures
// given on the command line, and prints r0.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

// `ps11 eval SHADER.psh [v0=r,g,b,a] [t0=u,v,w,q] [c0=x,y,z,w] ... [--precision P]
// [--max-value M] [--texN 0xAARRGGBB]`. Returns 0 on success, 1 on user errors, 2 on usage errors.
int cmdEval(const std::vector<std::string>& args);

}  // namespace ps11
