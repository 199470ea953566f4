// `ps11 test`: runs .ps11test files (docs/test-format.md). It parses every file, checks its
// [pixel shader] block (assembles and validates, or fails with the expected diagnostic) and
// runs its evals and eval probes on the executor; draws and pixel probes are counted as "not
// yet runnable" until the device exists.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

// `ps11 test FILE.ps11test... [--backend emu|gl|both] [--precision P] [--no-skip] [--stats] [-v]`. Returns 0 when
// every runnable check passed, 1 on any failure or parse error, 2 on usage errors.
int cmdTest(const std::vector<std::string>& args);

}  // namespace ps11
