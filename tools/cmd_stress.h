// `ps11 stress` (docs/stress.md): the numerical-stability suite of glare/stress.h on the command
// line: GLARE.md §7's pitfalls (prediction, measurement, fix), §6's metrics, robustness.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

int cmdStress(const std::vector<std::string>& args);

}  // namespace ps11
