// `ps11 hardware`: the hardware classes (ps11/hardware.h) and what each one changes.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

// Prints the table (or with --json one object per class). Returns a cli exit code.
int cmdHardware(const std::vector<std::string>& args);

}  // namespace ps11
