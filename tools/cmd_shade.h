// `ps11 shade`: one pixel shader over a half-pixel full-screen quad on images (docs/glare/README.md
// "Running one shader"), on either renderer.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

int cmdShade(const std::vector<std::string>& args);

}  // namespace ps11
