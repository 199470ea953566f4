// Helpers of the device tests (test_device.cpp, test_device_textures.cpp, test_device_blit.cpp):
// a lockable render target filled from a function of (x, y), and a substring test.
#pragma once

#include <catch2/catch.hpp>

#include <cstring>
#include <string>

#include "emu/device.h"

namespace devicetest {

using namespace emu;

// A lockable render target filled from a function of (x, y) giving 0xAARRGGBB.
template <class F>
inline Handle makeTarget(Device& dev, UINT w, UINT h, F colour, D3DFORMAT fmt = D3DFMT_A8R8G8B8) {
    Handle rt{};
    REQUIRE(dev.CreateRenderTarget(w, h, fmt, 1, &rt) == D3D_OK);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(rt, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < h; ++y)
        for (UINT x = 0; x < w; ++x) {
            const uint32_t c = colour(x, y);
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + x * 4, &c, 4);
        }
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
    return rt;
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace devicetest
