// `ps11 golden`: golden disassembly of the shader corpus and the round-trip property
// (text → tokens → text → tokens identical). Golden files change only with --regen.
#pragma once

#include <string>
#include <vector>

namespace ps11::cli {

int cmdGolden(const std::vector<std::string>& args);

}  // namespace ps11::cli
