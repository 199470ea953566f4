// Unit tests for the disassembler stage (ps11/disassembler.h): the spec's reference encodings
// print in canonical form, every modifier/mask/selector spelling, and def values that read
// back to the same bits.
#include <catch2/catch.hpp>

#include <bit>
#include <charconv>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "ps11/decoder.h"
#include "ps11/disassembler.h"

using namespace ps11;

namespace {

std::string disasmTokens(const std::vector<uint32_t>& tokens) {
    Diagnostics diags;
    const auto program = decode(tokens, 0, diags);
    INFO(diags.formatAll());
    REQUIRE(program.has_value());
    return disassemble(*program);
}

// Formats one instruction given as tokens (without version and end) in the version.
std::string line(int minor, std::vector<uint32_t> body) {
    body.insert(body.begin(), 0xFFFF0100u | uint32_t(minor));
    body.push_back(0x0000FFFF);
    const std::string text = disasmTokens(body);
    const size_t start = text.find('\n') + 1;
    return text.substr(start, text.size() - start - 1);
}

Instruction makeInst(std::string_view mnemonic, int minor) {
    Instruction inst;
    inst.info = findOpcode(mnemonic, minor);
    REQUIRE(inst.info != nullptr);
    return inst;
}

}  // namespace

TEST_CASE("disassembler: spec 5.7 reference encodings", "[disassembler]") {
    CHECK(disasmTokens({0xFFFF0101, 0x00000042, 0xB00F0000, 0x00000002, 0x80070000, 0x80E40000, 0x80E40001,
                        0x40000001, 0x80080000, 0xB0E40000, 0x0000FFFF}) ==
          "ps_1_1\ntex t0\nadd r0.rgb, r0, r1\n+mov r0.a, t0\n");
    CHECK(line(1, {0x00000001, 0x8E0F0000, 0x80E40001}) == "mov_d4 r0, r1");
    CHECK(line(1, {0x00000051, 0xA00F0002, 0, 0, 0, 0}) == "def c2, 0, 0, 0, 0");
    CHECK(line(3, {0x00000045, 0xB00F0001, 0xB0E40000}) == "texreg2ar t1, t0");
    CHECK(line(3, {0x0000004C, 0xB00F0003, 0xB0E40000, 0xA0E40000}) == "texm3x3spec t3, t0, c0");
    CHECK(line(3, {0x00000001, 0x811F0000, 0x86E40001}) == "mov_x2_sat r0, 1-r1");
    CHECK(line(3, {0x00000001, 0x82180000, 0x85FF0001}) == "mov_x4_sat r0.a, -r1_bx2.a");
    CHECK(line(4, {0x00000059, 0x80030001, 0xA0E40000, 0x80E40000}) == "bem r1.rg, c0, r0");
    CHECK(disasmTokens({0xFFFF0104, 0x00000002, 0x80070000, 0x80E40001, 0x80E40002, 0x40000002, 0x80080000,
                        0x80E40001, 0x80E40002, 0x0000FFFF}) == "ps_1_4\nadd r0.rgb, r1, r2\n+add r0.a, r1, r2\n");
}

TEST_CASE("disassembler: spec 5.6 texture opcodes per version", "[disassembler]") {
    CHECK(line(1, {0x00000042, 0xB00F0000}) == "tex t0");
    CHECK(line(2, {0x00000040, 0xB00F0000}) == "texcoord t0");
    CHECK(line(3, {0x00000041, 0xB00F0000}) == "texkill t0");
    CHECK(line(4, {0x00000042, 0x800F0000, 0xB0E40000}) == "texld r0, t0");
    CHECK(line(4, {0x00000040, 0x800F0000, 0xB0E40000}) == "texcrd r0, t0");
    CHECK(line(4, {0x00000040, 0x80070001, 0xB0A40000}) == "texcrd r1.rgb, t0.rgb");
    CHECK(line(4, {0x00000042, 0x800F0005, 0x89E40002}) == "texld r5, r2_dz");
    CHECK(line(4, {0x00000042, 0x800F0001, 0xBAF40000}) == "texld r1, t0_dw.rga");
    CHECK(line(4, {0x00000057, 0x800F0005}) == "texdepth r5");
    CHECK(line(4, {0x0000FFFD}) == "phase");
    CHECK(line(1, {0x00000000}) == "nop");
}

TEST_CASE("disassembler: source modifiers", "[disassembler]") {
    const char* expected[] = {"r0",     "-r0",   "r0_bias", "-r0_bias", "r0_bx2", "-r0_bx2",
                              "1-r0",   "r0_x2", "-r0_x2",  "r0_dz",    "r0_dw"};
    for (unsigned mod = 0; mod <= 10; ++mod) {
        Instruction inst = makeInst("mov", 4);
        inst.src[0].mod = SrcMod(mod);
        CHECK(formatInstruction(inst, Version{1, 4}) == std::string("mov r0, ") + expected[mod]);
    }
    Instruction inst = makeInst("mul", 4);
    inst.src[0] = Src{RegType::Input, 1, 0xFF, SrcMod::SignNeg, {}};
    inst.src[1] = Src{RegType::Const, 7, 0x00, SrcMod::Comp, {}};
    CHECK(formatInstruction(inst, Version{1, 4}) == "mul r0, -v1_bx2.a, 1-c7.r");
}

TEST_CASE("disassembler: write masks and instruction modifiers", "[disassembler]") {
    const char* masks[16] = {"",     ".r",   ".g",   ".rg",   ".b",   ".rb",   ".gb",   ".rgb",
                             ".a",   ".ra",  ".ga",  ".rga",  ".ba",  ".rba",  ".gba",  ""};
    for (int m = 1; m < 16; ++m) {
        Instruction inst = makeInst("mov", 4);
        inst.dst.mask = uint8_t(m);
        CHECK(formatInstruction(inst, Version{1, 4}) == std::string("mov r0") + masks[m] + ", r0");
    }
    const std::pair<int, const char*> shifts[] = {{1, "_x2"}, {2, "_x4"}, {3, "_x8"},
                                                  {-1, "_d2"}, {-2, "_d4"}, {-3, "_d8"}};
    for (auto [shift, text] : shifts) {
        Instruction inst = makeInst("add", 4);
        inst.dst.shift = int8_t(shift);
        inst.dst.saturate = true;
        inst.coissue = true;
        CHECK(formatInstruction(inst, Version{1, 4}) == std::string("+add") + text + "_sat r0, r0, r0");
    }
}

TEST_CASE("disassembler: swizzles", "[disassembler]") {
    auto fmt = [](uint8_t sw) {
        Instruction inst = makeInst("mov", 4);
        inst.src[0].swizzle = sw;
        const std::string text = formatInstruction(inst, Version{1, 4});
        return text.substr(std::string("mov r0, r0").size());
    };
    CHECK(fmt(0xE4).empty());
    CHECK(fmt(0x00) == ".r");
    CHECK(fmt(0x55) == ".g");
    CHECK(fmt(0xAA) == ".b");
    CHECK(fmt(0xFF) == ".a");
    CHECK(fmt(0xA4) == ".rgb");
    CHECK(fmt(0xF4) == ".rga");
    CHECK(fmt(0x54) == ".rg");
    CHECK(fmt(0xC0) == ".rrra");
    CHECK(fmt(0x1B) == ".abgr");
    // Every swizzle prints differently, so the text determines the token.
    std::set<std::string> seen;
    for (int sw = 0; sw < 256; ++sw) seen.insert(fmt(uint8_t(sw)));
    CHECK(seen.size() == 256);
}

TEST_CASE("disassembler: def values read back to the same bits", "[disassembler]") {
    Instruction def = makeInst("def", 1);
    def.dst = Dst{RegType::Const, 0, kMaskAll, false, 0, {}};
    def.defBits = {std::bit_cast<uint32_t>(0.5f), std::bit_cast<uint32_t>(0.25f), std::bit_cast<uint32_t>(1.0f), 0};
    CHECK(formatInstruction(def, Version{1, 1}) == "def c0, 0.5, 0.25, 1, 0");

    def.defBits = {std::bit_cast<uint32_t>(-0.0f), std::bit_cast<uint32_t>(0.1f), std::bit_cast<uint32_t>(-1.5f),
                   std::bit_cast<uint32_t>(1e10f)};
    CHECK(formatInstruction(def, Version{1, 1}) == "def c0, -0, 0.1, -1.5, 1e+10");

    def.defBits = {0x7FC00000, 0xFF800000, 0x7F800000, 0x7FA12345};
    CHECK(formatInstruction(def, Version{1, 1}) ==
          "def c0, bits(0x7fc00000), bits(0xff800000), bits(0x7f800000), bits(0x7fa12345)");

    // Shortest decimal round trip over a spread of bit patterns, including subnormals.
    const uint32_t samples[] = {0x00000001, 0x007FFFFF, 0x00800000, 0x3DCCCCCD, 0x3F7FFFFF, 0x3F800001,
                                0x7F7FFFFF, 0xFF7FFFFF, 0x80000001, 0x3EAAAAAB, 0x4B800001, 0xC0490FDB};
    for (uint32_t bits : samples) {
        def.defBits = {bits, bits, bits, bits};
        const std::string text = formatInstruction(def, Version{1, 1});
        const size_t comma = text.find(", ", text.find("c0")) + 2;
        const std::string first = text.substr(comma, text.find(',', comma) - comma);
        float back = 0;
        const auto res = std::from_chars(first.data(), first.data() + first.size(), back);
        INFO(first);
        CHECK(res.ptr == first.data() + first.size());
        CHECK(std::bit_cast<uint32_t>(back) == bits);
    }
}

TEST_CASE("disassembler: header per version", "[disassembler]") {
    for (int minor = 1; minor <= 4; ++minor) {
        Program p;
        p.version = Version{1, minor};
        CHECK(disassemble(p) == "ps_1_" + std::to_string(minor) + "\n");
    }
}

TEST_CASE("disassembler: decode → text is stable over the reference programs", "[disassembler]") {
    // Decoding and re-printing the same tokens twice gives identical text (no hidden state).
    const std::vector<uint32_t> tokens{0xFFFF0103, 0x00000051, 0xA00F0001, 0x3F000000, 0xBF800000, 0x7FC00000,
                                       0x00000000, 0x00000042, 0xB00F0000, 0x00000001, 0x82180000, 0x85FF0001,
                                       0x00000001, 0x811F0000, 0x86E40001, 0x0000FFFF};
    const std::string a = disasmTokens(tokens);
    CHECK(a == "ps_1_3\ndef c1, 0.5, -1, bits(0x7fc00000), 0\ntex t0\nmov_x4_sat r0.a, -r1_bx2.a\n"
               "mov_x2_sat r0, 1-r1\n");
    CHECK(disasmTokens(tokens) == a);
}
