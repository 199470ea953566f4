// `ps11 hardware`: lists the emulated GPUs, one row per hardware class, with every behaviour the
// class fixes (docs/precision.md "Hardware classes" has the sources).
#include "tools/cmd_hardware.h"

#include <cstdio>
#include <iostream>

#include "ps11/hardware.h"
#include "ps11/json_internal.h"
#include "tools/cli_util.h"

namespace ps11 {

namespace {

const char* cndName(CoissuedCnd c) { return c == CoissuedCnd::Sequential ? "sequential" : "parallel"; }

}  // namespace

int cmdHardware(const std::vector<std::string>& args) {
    bool json = false;
    for (const std::string& a : args) {
        if (a == "--json") {
            json = true;
        } else if (a == "-h" || a == "--help") {
            std::cout << "usage: ps11 hardware [--json]\n";
            return cli::kOk;
        } else {
            std::cerr << "ps11: hardware: unknown argument '" << a << "'\nusage: ps11 hardware [--json]\n";
            return cli::kUsage;
        }
    }
    if (json) {
        json::Json rows = json::Json::array();
        for (const HardwareClass& h : hardwareClasses())
            rows.push_back({{"name", h.name},
                            {"kind", h.kind},
                            {"gpus", h.gpus},
                            {"max_version", "ps_1_" + std::to_string(h.maxMinor)},
                            {"precision", precisionName(h.precision)},
                            {"max_value", json::rounded(double(h.maxValue), "%g")},
                            {"signed_decode", signedDecodeName(h.signedDecode)},
                            {"coissued_cnd", cndName(h.coissuedCnd)},
                            {"bilinear_weight_bits", h.bilinearWeightBits},
                            {"default", &h == &defaultHardware(1) || &h == &defaultHardware(4)}});
        std::cout << json::dump(rows, 1) << "\n";
        return cli::kOk;
    }
    std::printf("%-11s %-10s %-7s %-8s %9s %-11s %-11s %7s  %s\n", "hardware", "kind", "up to", "profile", "max value",
                "signed", "+cnd reads", "weights", "stands for");
    for (const HardwareClass& h : hardwareClasses()) {
        std::printf("%-11.*s %-10.*s ps_1_%d   %-8s %9g %-11s %-11s %5d b  %.*s%s\n", int(h.name.size()), h.name.data(),
                    int(h.kind.size()), h.kind.data(), h.maxMinor, precisionName(h.precision), double(h.maxValue),
                    signedDecodeName(h.signedDecode), cndName(h.coissuedCnd), h.bilinearWeightBits,
                    int(h.gpus.size()), h.gpus.data(),
                    &h == &defaultHardware(1)   ? " (default)"
                    : &h == &defaultHardware(4) ? " (default for ps_1_4)"
                                                : "");
    }
    std::printf("\n--hardware H picks one (eval, test, demo); --precision and max_value override its profile and "
                "MaxValue.\nSources for every value: docs/precision.md \"Hardware classes\".\n");
    return cli::kOk;
}

}  // namespace ps11
