// `ps11 bench` (docs/bench.md): run time against error — a sweep of techniques, presets, settings,
// hardware classes and renderers (glare/sweep.h), its table, and the Pareto front.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

int cmdBench(const std::vector<std::string>& args);

}  // namespace ps11
