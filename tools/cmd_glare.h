// `ps11 glare` (docs/glare/README.md): the glare techniques on built-in scenes or the user's
// images, on either renderer, with the pass graph, per-pass dumps, the pass-isolated
// cross-check and the fits-ps_1_1 report.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

int cmdGlare(const std::vector<std::string>& args);

}  // namespace ps11
