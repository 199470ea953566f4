// What a stage of a device call reports when it refuses: the D3D9 return code, the E41xx code
// (docs/diagnostics.md) and the message without the code. The device front's draw stages
// (emu/device_draw.cpp), the fixed-function lowering (emu/ffp.h), the output merger's state check
// (emu/output_merger.h) and the renderers (emu/renderer.h) all report this; the front prefixes
// the call's name and records it as the call's DeviceError (emu/device.h).
#pragma once

#include <string>

#include "emu/d3d9types.h"

namespace emu {

struct CallError {
    HRESULT hr = D3D_OK;
    std::string code;     // "E4121"
    std::string message;  // without the code: "the executor refused pixel shader 3"
};

}  // namespace emu
