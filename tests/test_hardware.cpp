// Hardware classes (ps11/hardware.h): the table, the signed-texel rules at their extremes, and
// the resolution of a class with its overrides; the one CPU feature query.
#include <catch2/catch.hpp>

#include "emu/device.h"
#include "ps11/cpu_features.h"
#include "ps11/hardware.h"
#include "ps11/texture.h"

using namespace ps11;

TEST_CASE("hardware: the table and its defaults", "[hardware]") {
    REQUIRE(hardwareClasses().size() == 5);
    CHECK(&defaultHardware(1) == findHardware("geforce4"));
    CHECK(&defaultHardware(3) == findHardware("geforce4"));
    CHECK(&defaultHardware(4) == findHardware("RADEON8500"));
    CHECK(findHardware("voodoo") == nullptr);
    for (const HardwareClass& h : hardwareClasses()) {
        CHECK(findHardware(h.name) == &h);
        CHECK(&hardwareClasses()[size_t(hardwareIndex(h))] == &h);
        CHECK(h.maxMinor >= 1);
        CHECK(h.maxMinor <= 4);
    }
    CHECK(findHardware("geforce3")->maxMinor == 1);
    CHECK(findHardware("geforce4")->maxMinor == 3);
    CHECK(findHardware("geforce4")->maxValue == 1.0f);
    CHECK(findHardware("radeon8500")->maxValue == 8.0f);
    CHECK(unknownHardwareMessage("geforce5") ==
          "unknown hardware class 'geforce5' (expected geforce4, geforce3, radeon8500, d3d9, geforce7); "
          "did you mean 'geforce4'?");
}

TEST_CASE("hardware: signed channels at -max-1, -max, 0, +max under every rule", "[hardware]") {
    auto eq = [](SignedValue v, int64_t num, int64_t den) { return v.num * den == num * v.den; };
    // snorm: the most negative code reads -1.
    CHECK(eq(decodeSignedChannel(SignedDecode::Snorm, -128, 8), -1, 1));
    CHECK(eq(decodeSignedChannel(SignedDecode::Snorm, -127, 8), -1, 1));
    CHECK(eq(decodeSignedChannel(SignedDecode::Snorm, 127, 8), 1, 1));
    CHECK(eq(decodeSignedChannel(SignedDecode::Snorm, -15, 5), -1, 1));
    CHECK(eq(decodeSignedChannel(SignedDecode::Snorm, 7, 5), 7, 15));
    CHECK(eq(decodeSignedChannel(SignedDecode::Snorm, -32768, 16), -1, 1));
    // unclamped (R200): -128/127 stays below -1.
    CHECK(eq(decodeSignedChannel(SignedDecode::Unclamped, -128, 8), -128, 127));
    CHECK(eq(decodeSignedChannel(SignedDecode::Unclamped, -16, 5), -16, 15));
    CHECK(eq(decodeSignedChannel(SignedDecode::Unclamped, 0, 8), 0, 1));
    // asymmetric: negative codes over 2^(n-1), positive over 2^(n-1) - 1.
    CHECK(eq(decodeSignedChannel(SignedDecode::Asymmetric, -16, 5), -1, 1));
    CHECK(eq(decodeSignedChannel(SignedDecode::Asymmetric, -15, 5), -15, 16));
    CHECK(eq(decodeSignedChannel(SignedDecode::Asymmetric, 15, 5), 1, 1));
    CHECK(eq(decodeSignedChannel(SignedDecode::Asymmetric, -127, 8), -127, 128));
    CHECK(eq(decodeSignedChannel(SignedDecode::Asymmetric, 127, 8), 1, 1));
    // widen8: 5-bit abcde -> abcdeabc, then snorm of the byte (GeForce 7 in Wine's test:
    // 15 -> 0x7b, -7 -> 0xce, -3 -> 0xef, -16 -> 0x84).
    CHECK(eq(decodeSignedChannel(SignedDecode::Widen8, 15, 5), 123, 127));
    CHECK(eq(decodeSignedChannel(SignedDecode::Widen8, -7, 5), -50, 127));
    CHECK(eq(decodeSignedChannel(SignedDecode::Widen8, -3, 5), -17, 127));
    CHECK(eq(decodeSignedChannel(SignedDecode::Widen8, -16, 5), -124, 127));
    CHECK(eq(decodeSignedChannel(SignedDecode::Widen8, 0, 5), 0, 1));
    CHECK(eq(decodeSignedChannel(SignedDecode::Widen8, -128, 8), -1, 1));  // 8 bits and more: snorm
}

TEST_CASE("hardware: resolving a class with overrides", "[hardware]") {
    HardwareConfig c = resolveHardware(nullptr, 2, std::nullopt, 0);
    CHECK(c.hardware == findHardware("geforce4"));
    CHECK(c.precision == Precision::Fx8);
    CHECK(c.maxValue == 1.0f);
    CHECK(c.weightBits == 8);
    CHECK(c.describe() == "geforce4 (1.1-class), fx8, max value 1");
    c = resolveHardware(nullptr, 4, std::nullopt, 0);
    CHECK(c.hardware == findHardware("radeon8500"));
    CHECK(c.describe() == "radeon8500 (1.4-class), fx12, max value 8");
    // An overriding profile brings its own filter weights; the class's float profile has 8 bits.
    c = resolveHardware(findHardware("geforce4"), 1, Precision::Float, 2);
    CHECK(c.weightBits == 0);
    CHECK(c.maxValue == 2.0f);
    CHECK(c.describe() == "geforce4 (1.1-class), float (override), max value 2 (override)");
    c = resolveHardware(findHardware("d3d9"), 1, std::nullopt, 0);
    CHECK(c.weightBits == 8);
    CHECK(c.precision == Precision::Float);
    c = resolveHardware(findHardware("d3d9"), 1, Precision::Ideal, 0);
    CHECK(c.weightBits == 0);
    // d3d9's 65504 does not fit fx12's grid: capped to the largest value it holds.
    c = resolveHardware(findHardware("d3d9"), 1, Precision::Fx12, 0);
    CHECK(c.maxValue == 4112.0f);
    CHECK(c.maxValueCapped);
    c = resolveHardware(findHardware("d3d9"), 1, Precision::Fx8, 0);
    CHECK(c.maxValue == 65504.0f);
    CHECK(!c.maxValueCapped);
}

TEST_CASE("hardware: the device decodes signed textures by its class", "[hardware][device]") {
    // V8U8 U = -128, V = -127: snorm reads (-1, -1), unclamped (-128/127, -1), asymmetric
    // (-1, -127/128).
    struct Case {
        const char* name;
        float u, v;
    } cases[] = {{"geforce4", -1.0f, -1.0f},
                 {"radeon8500", float(-128.0 / 127.0), -1.0f},
                 {"d3d9", -1.0f, float(-127.0 / 128.0)}};
    for (const Case& c : cases) {
        emu::DeviceOptions o;
        o.hardware = findHardware(c.name);
        emu::Device dev(o);
        emu::Handle tex{};
        REQUIRE(dev.CreateTexture(1, 1, 1, 0, emu::D3DFMT_V8U8, emu::D3DPOOL_MANAGED, &tex) == emu::D3D_OK);
        emu::D3DLOCKED_RECT lr;
        REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == emu::D3D_OK);
        static_cast<uint8_t*>(lr.pBits)[0] = 0x80;  // U
        static_cast<uint8_t*>(lr.pBits)[1] = 0x81;  // V
        REQUIRE(dev.UnlockRect(tex, 0) == emu::D3D_OK);
        auto sampled = dev.sampledTexture(tex);
        REQUIRE(sampled);
        INFO(c.name);
        CHECK(sampled->signedDecode() == o.hardware->signedDecode);
        const std::array<float, 4> t = sampled->texelValue(0, 0, 0);
        CHECK(t[0] == c.u);
        CHECK(t[1] == c.v);
        CHECK(t[2] == 1.0f);
        CHECK(t[3] == 1.0f);
    }
}

TEST_CASE("cpu features: the one query agrees with the compiler's", "[cpu]") {
#if defined(__x86_64__)
    __builtin_cpu_init();
    CHECK(ps11::cpuFeatures().avx2 == bool(__builtin_cpu_supports("avx2")));
    CHECK(ps11::cpuFeatures().fma == bool(__builtin_cpu_supports("fma")));
    CHECK(ps11::cpuFeatures().avx512 == bool(__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                                             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl")));
#endif
    CHECK(&ps11::cpuFeatures() == &ps11::cpuFeatures());  // queried once
}
