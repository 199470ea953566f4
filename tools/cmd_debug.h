// `ps11 debug`: one pixel of a shader, instruction by instruction, on the emulated hardware class
// beside `ideal`, with why the two differ and where they first part (docs/debug.md).
#pragma once

#include <string>
#include <vector>

namespace ps11 {

// `ps11 debug SHADER.psh [the inputs of ps11 eval] [--hardware H] [--json]`. Returns 0 on
// success, 1 on user errors, 2 on usage errors.
int cmdDebug(const std::vector<std::string>& args);

}  // namespace ps11
