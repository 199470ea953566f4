// `ps11 test`: runs .ps11test files (docs/test-format.md). Today it parses every file and
// checks its [pixel shader] block (assembles and validates, or fails with the expected
// diagnostic); draws, evals and probes are counted as "not yet runnable" until the executor
// and the device exist.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

// `ps11 test FILE.ps11test... [--backend emu|gl|both] [--precision P] [-v]`. Returns 0 when
// every runnable check passed, 1 on any failure or parse error, 2 on usage errors.
int cmdTest(const std::vector<std::string>& args);

}  // namespace ps11
