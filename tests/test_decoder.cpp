// Unit tests for the decoder stage (ps11/decoder.h): reference encodings from ps1x-spec.md
// §5.6/§5.7 decode to the expected IR, and every malformed stream gives the documented P3xxx
// code at the right token index with the token's hex value in the message.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "ps11/decoder.h"
#include "ps11/disassembler.h"

using namespace ps11;

namespace {

struct Result {
    Diagnostics diags;
    std::optional<Program> program;
};

Result run(const std::vector<uint32_t>& tokens) {
    Result r;
    const uint32_t file = r.diags.addFile("in.bin");
    r.program = decode(tokens, file, r.diags);
    return r;
}

Program decodeOk(const std::vector<uint32_t>& tokens) {
    Result r = run(tokens);
    INFO(r.diags.formatAll());
    REQUIRE(r.program.has_value());
    REQUIRE_FALSE(r.diags.hasErrors());
    return *r.program;
}

// The first error must carry this code and token index, and its formatted text the hex.
void requireError(const Result& r, const char* code, int tokenIndex, const char* hexText) {
    INFO(r.diags.formatAll());
    REQUIRE_FALSE(r.program.has_value());
    REQUIRE(r.diags.hasErrors());
    const Diagnostic* first = nullptr;
    for (const Diagnostic& d : r.diags.all())
        if (d.severity == Severity::Error) {
            first = &d;
            break;
        }
    REQUIRE(first != nullptr);
    CHECK(first->code == code);
    CHECK(first->loc.tokenIndex == tokenIndex);
    const std::string text = r.diags.format(*first);
    CHECK(text.find("in.bin: token " + std::to_string(tokenIndex) + ": error " + code) == 0);
    if (hexText) CHECK(text.find(hexText) != std::string::npos);
}

constexpr uint32_t kPs11 = 0xFFFF0101, kPs13 = 0xFFFF0103, kPs14 = 0xFFFF0104, kEnd = 0x0000FFFF;

}  // namespace

TEST_CASE("decoder: spec 5.7 ps_1_1 tex/add/+mov", "[decoder]") {
    const Program p = decodeOk({kPs11, 0x00000042, 0xB00F0000, 0x00000002, 0x80070000, 0x80E40000, 0x80E40001,
                                0x40000001, 0x80080000, 0xB0E40000, kEnd});
    CHECK(p.version == Version{1, 1});
    CHECK(p.versionLoc.tokenIndex == 0);
    REQUIRE(p.instructions.size() == 3);

    const Instruction& tex = p.instructions[0];
    CHECK(tex.info->mnemonic == "tex");
    CHECK(tex.loc.tokenIndex == 1);
    CHECK(tex.dst.type == RegType::Texture);
    CHECK(tex.dst.index == 0);
    CHECK(tex.dst.mask == kMaskAll);
    CHECK(tex.dst.loc.tokenIndex == 2);

    const Instruction& add = p.instructions[1];
    CHECK(add.opcode() == Opcode::Add);
    CHECK(add.loc.tokenIndex == 3);
    CHECK_FALSE(add.coissue);
    CHECK(add.dst.mask == kMaskRGB);
    CHECK(add.src[0].type == RegType::Temp);
    CHECK(add.src[0].index == 0);
    CHECK(add.src[1].index == 1);
    CHECK(add.src[1].swizzle == 0xE4);
    CHECK(add.src[1].loc.tokenIndex == 6);

    const Instruction& mov = p.instructions[2];
    CHECK(mov.opcode() == Opcode::Mov);
    CHECK(mov.coissue);
    CHECK(mov.dst.mask == kMaskA);
    CHECK(mov.src[0].type == RegType::Texture);
    CHECK(mov.loc.tokenIndex == 7);
}

TEST_CASE("decoder: spec 5.7 modifiers and def", "[decoder]") {
    SECTION("mov_d4 r0, r1") {
        const Program p = decodeOk({kPs11, 0x00000001, 0x8E0F0000, 0x80E40001, kEnd});
        CHECK(p.instructions[0].dst.shift == -2);
        CHECK_FALSE(p.instructions[0].dst.saturate);
    }
    SECTION("def c2, 0, 0, 0, 0") {
        const Program p = decodeOk({kPs11, 0x00000051, 0xA00F0002, 0, 0, 0, 0, kEnd});
        const Instruction& def = p.instructions[0];
        CHECK(def.opcode() == Opcode::Def);
        CHECK(def.dst.type == RegType::Const);
        CHECK(def.dst.index == 2);
        CHECK(def.defBits == std::array<uint32_t, 4>{0, 0, 0, 0});
    }
    SECTION("def payload words are raw, bit 31 may be clear or set") {
        const Program p = decodeOk({kPs11, 0x00000051, 0xA00F0000, 0x3F000000, 0xBF800000, 0x7FC00000, 0x00000001, kEnd});
        CHECK(p.instructions[0].defBits == std::array<uint32_t, 4>{0x3F000000, 0xBF800000, 0x7FC00000, 1});
        CHECK(p.instructions[0].defValue(0) == 0.5f);
    }
    SECTION("mov_x2_sat r0, 1 - r1 (ps_1_3)") {
        const Program p = decodeOk({kPs13, 0x00000001, 0x811F0000, 0x86E40001, kEnd});
        CHECK(p.instructions[0].dst.shift == 1);
        CHECK(p.instructions[0].dst.saturate);
        CHECK(p.instructions[0].src[0].mod == SrcMod::Comp);
    }
    SECTION("mov_x4_sat r0.a, -r1_bx2.a (ps_1_3)") {
        const Program p = decodeOk({kPs13, 0x00000001, 0x82180000, 0x85FF0001, kEnd});
        const Instruction& i = p.instructions[0];
        CHECK(i.dst.shift == 2);
        CHECK(i.dst.saturate);
        CHECK(i.dst.mask == kMaskA);
        CHECK(i.src[0].mod == SrcMod::SignNeg);
        CHECK(i.src[0].swizzle == 0xFF);
    }
    SECTION("texreg2ar t1, t0 and texm3x3spec t3, t0, c0 (ps_1_3)") {
        const Program p = decodeOk({kPs13, 0x00000045, 0xB00F0001, 0xB0E40000, 0x0000004C, 0xB00F0003, 0xB0E40000,
                                    0xA0E40000, kEnd});
        REQUIRE(p.instructions.size() == 2);
        CHECK(p.instructions[0].opcode() == Opcode::TexReg2AR);
        CHECK(p.instructions[1].opcode() == Opcode::TexM3x3Spec);
        CHECK(p.instructions[1].src[1].type == RegType::Const);
        CHECK(p.instructions[1].loc.tokenIndex == 4);
    }
}

TEST_CASE("decoder: ps_1_4 operand layouts (spec 5.6)", "[decoder]") {
    const Program p = decodeOk({kPs14, 0x00000042, 0x800F0000, 0xB0E40000,  // texld r0, t0
                                0x00000040, 0x800F0000, 0xB0E40000,          // texcrd r0, t0
                                0x00000042, 0x800F0005, 0x89E40002,          // texld r5, r2_dz
                                0x0000FFFD,                                  // phase
                                0x00000057, 0x800F0005,                      // texdepth r5
                                0x00000059, 0x80030001, 0xA0E40000, 0x80E40000,  // bem r1.rg, c0, r0
                                0x00000002, 0x80070000, 0x80E40001, 0x80E40002,  // add r0.rgb, r1, r2
                                0x40000002, 0x80080000, 0x80E40001, 0x80E40002,  // +add r0.a, r1, r2
                                kEnd});
    REQUIRE(p.instructions.size() == 8);
    CHECK(p.instructions[0].info->mnemonic == "texld");
    CHECK(p.instructions[1].info->mnemonic == "texcrd");
    CHECK(p.instructions[2].src[0].mod == SrcMod::Dz);
    CHECK(p.instructions[3].opcode() == Opcode::Phase);
    CHECK(p.instructions[3].loc.tokenIndex == 10);
    CHECK(p.instructions[4].opcode() == Opcode::TexDepth);
    CHECK(p.instructions[5].dst.mask == (kMaskR | kMaskG));
    CHECK(p.instructions[7].coissue);
}

TEST_CASE("decoder: comments are skipped anywhere after the version token", "[decoder]") {
    const Program p = decodeOk({kPs11, 0x0002FFFE, 0xDEADBEEF, 0x00000042,  // comment whose payload looks like tex
                                0x00000042, 0xB00F0000, 0x0000FFFE,          // empty comment
                                0x0001FFFE, kEnd,                            // payload is the end token
                                kEnd});
    REQUIRE(p.instructions.size() == 1);
    CHECK(p.instructions[0].loc.tokenIndex == 4);
}

TEST_CASE("decoder: bad version tokens", "[decoder]") {
    requireError(run({}), "P3003", 0, nullptr);
    requireError(run({0x12345678, kEnd}), "P3003", 0, "(0x12345678)");
    requireError(run({0x00000042, kEnd}), "P3003", 0, "(0x00000042)");
    requireError(run({0xFFFF0100, kEnd}), "P3017", 0, "ps_1_0");
    requireError(run({0xFFFE0101, kEnd}), "P3017", 0, "vs_1_1 (0xfffe0101)");
    requireError(run({0xFFFF0200, kEnd}), "P3017", 0, "(0xffff0200)");
    requireError(run({0xFFFF0300, kEnd}), "P3017", 0, "ps_3_0");
    requireError(run({0xFFFF0105, kEnd}), "P3017", 0, "ps_1_5");
}

TEST_CASE("decoder: unknown opcodes stop decoding", "[decoder]") {
    SECTION("reserved texm3x3diff 0x4b") {
        const Result r = run({kPs11, 0x00000042, 0xB00F0000, 0x00000042, 0xB00F0001, 0x00000001, 0x800F0000,
                              0xB0E40000, 0x0000004B, 0xB00F0002, 0xB0E40000, kEnd});
        requireError(r, "P3004", 8, "unknown opcode 0x0000004b (0x0000004b)");
        CHECK(r.diags.errorCount() == 1);
    }
    SECTION("rcp 0x06 is not a ps 1.x opcode") {
        requireError(run({kPs11, 0x00000006, 0x800F0000, 0x80E40000, kEnd}), "P3004", 1, "(0x00000006)");
    }
    SECTION("0x4b with the co-issue bit names the full token") {
        requireError(run({kPs11, 0x4000004B, kEnd}), "P3004", 1, "(0x4000004b)");
    }
}

TEST_CASE("decoder: instruction token reserved bits", "[decoder]") {
    requireError(run({kPs11, 0x80000001, 0x800F0000, 0x80E40000, kEnd}), "P3005", 1, "(0x80000001)");
    requireError(run({kPs11, 0x20000001, 0x800F0000, 0x80E40000, kEnd}), "P3005", 1, "bit 31/29");
    requireError(run({kPs11, 0x10000001, 0x800F0000, 0x80E40000, kEnd}), "P3005", 1, "predicated");
    requireError(run({kPs11, 0x02000001, 0x800F0000, 0x80E40000, kEnd}), "P3005", 1, "length");
    requireError(run({kPs11, 0x00010042, 0xB00F0000, kEnd}), "P3005", 1, "opcode-specific");
    requireError(run({kPs11, 0x4000FFFF}), "P3005", 1, "end token (0x4000ffff)");
    requireError(run({kPs11, 0x8000FFFE, kEnd}), "P3005", 1, "comment token (0x8000fffe)");
}

TEST_CASE("decoder: truncated streams", "[decoder]") {
    SECTION("operands past the end") {
        requireError(run({kPs11, 0x00000002, 0x80070000, 0x80E40000}), "P3006", 1,
                     "truncated instruction 'add' (0x00000002)");
    }
    SECTION("def payload past the end") {
        requireError(run({kPs11, 0x00000051, 0xA00F0000, 0, 0, kEnd}), "P3006", 1, "needs 5 operand tokens");
    }
    SECTION("missing end token") {
        const Result r = run({kPs11, 0x00000042, 0xB00F0000});
        requireError(r, "P3007", 2, "(0xb00f0000)");
        CHECK(r.diags.errorCount() == 1);
    }
    SECTION("only a version token") { requireError(run({kPs11}), "P3007", 0, "(0xffff0101)"); }
    SECTION("comment length past the end") {
        requireError(run({kPs11, 0x0005FFFE, 0, 0, kEnd}), "P3008", 1, "(0x0005fffe)");
    }
    SECTION("maximum comment length does not overflow") {
        requireError(run({kPs11, 0x7FFFFFFE}), "P3008", 1, "32767 tokens");
    }
}

TEST_CASE("decoder: parameter token errors", "[decoder]") {
    SECTION("bad register type 4 (rastout)") {
        const Result r = run({kPs11, 0x00000001, 0x800F0000, 0xC00F0000, kEnd});
        requireError(r, "P3010", 3, "bad register type 4 (rastout) (0xc00f0000)");
    }
    SECTION("type bits 3-4 count: sampler 10") {
        requireError(run({kPs11, 0x00000001, 0xA00F0800 | 0x80000000, 0x80E40000, kEnd}), "P3010", 2, "sampler");
    }
    SECTION("bit 31 clear") {
        requireError(run({kPs11, 0x00000001, 0x000F0000, 0x80E40000, kEnd}), "P3009", 2, "(0x000f0000)");
    }
    SECTION("relative addressing") {
        requireError(run({kPs11, 0x00000001, 0x800F0000, 0x80E42000, kEnd}), "P3011", 3, "relative");
    }
    SECTION("reserved bits 14-15") {
        requireError(run({kPs11, 0x00000001, 0x800F4000, 0x80E40000, kEnd}), "P3011", 2, "(0x800f4000)");
    }
    SECTION("register number 256 does not fit") {
        requireError(run({kPs11, 0x00000001, 0x800F0100, 0x80E40000, kEnd}), "P3012", 2, "256");
    }
    SECTION("register numbers up to 255 decode (ranges are the validator's job)") {
        const Program p = decodeOk({kPs11, 0x00000001, 0x800F00FF, 0x90E40007, kEnd});
        CHECK(p.instructions[0].dst.index == 255);
        CHECK(p.instructions[0].src[0].type == RegType::Input);
        CHECK(p.instructions[0].src[0].index == 7);
    }
    SECTION("partial precision result modifier") {
        requireError(run({kPs11, 0x00000001, 0x802F0000, 0x80E40000, kEnd}), "P3013", 2, "partial precision");
    }
    SECTION("shift x16 has no ps 1.x form") {
        requireError(run({kPs11, 0x00000001, 0x840F0000, 0x80E40000, kEnd}), "P3014", 2, "(0x840f0000)");
        requireError(run({kPs11, 0x00000001, 0x880F0000, 0x80E40000, kEnd}), "P3014", 2, "-8");
    }
    SECTION("source modifier 11 (abs)") {
        requireError(run({kPs11, 0x00000001, 0x800F0000, 0x8BE40000, kEnd}), "P3015", 3, "(0x8be40000)");
    }
    SECTION("empty write mask") {
        requireError(run({kPs11, 0x00000001, 0x80000000, 0x80E40000, kEnd}), "P3016", 2, "(0x80000000)");
    }
}

TEST_CASE("decoder: several errors are collected", "[decoder]") {
    const Result r = run({kPs11, 0x00000002, 0xC00F0000, 0x8BE40000, 0x80E42000,  // three bad params
                          0x10000001, 0x800F0000, 0x80E40000,                     // predicated
                          kEnd});
    INFO(r.diags.formatAll());
    REQUIRE_FALSE(r.program.has_value());
    CHECK(r.diags.errorCount() == 4);
    CHECK(r.diags.has("P3010"));
    CHECK(r.diags.has("P3015"));
    CHECK(r.diags.has("P3011"));
    CHECK(r.diags.has("P3005"));
    CHECK(r.diags.all().back().loc.tokenIndex == 5);
}

TEST_CASE("decoder: error flood is capped", "[decoder]") {
    std::vector<uint32_t> tokens{kPs11};
    for (int i = 0; i < 200; ++i) {
        tokens.push_back(0x00000001);
        tokens.push_back(0xC00F0000);
        tokens.push_back(0xCBE42800);  // type 12 and relative: two errors per source
    }
    tokens.push_back(kEnd);
    const Result r = run(tokens);
    REQUIRE_FALSE(r.program.has_value());
    CHECK(r.diags.errorCount() == 32);
    CHECK(r.diags.all().back().severity == Severity::Note);
}

TEST_CASE("decoder: tokens after the end token are a warning", "[decoder]") {
    Result r = run({kPs11, 0x00000000, kEnd, 0x12345678, 0x9abcdef0});
    INFO(r.diags.formatAll());
    REQUIRE(r.program.has_value());
    CHECK_FALSE(r.diags.hasErrors());
    REQUIRE(r.diags.all().size() == 1);
    const Diagnostic& d = r.diags.all()[0];
    CHECK(d.severity == Severity::Warning);
    CHECK(d.code == "P3018");
    CHECK(d.loc.tokenIndex == 3);
    CHECK(r.diags.format(d).find("in.bin: token 3: warning P3018: 2 token(s)") == 0);
    CHECK(r.diags.format(d).find("(0x12345678)") != std::string::npos);
}

TEST_CASE("decoder: opcode rows follow the version's token layout", "[decoder]") {
    // 0x42 in ps_1_1 is tex (dst only): the following 0xB0E40000 would be a bad instruction token.
    requireError(run({kPs11, 0x00000042, 0x800F0000, 0xB0E40000, kEnd}), "P3005", 3, "(0xb0e40000)");
    // Version-illegal but known opcodes decode; the validator rejects them.
    const Program p = decodeOk({kPs11, 0x00000059, 0x80030001, 0xA0E40000, 0x80E40000, kEnd});
    CHECK(p.instructions[0].opcode() == Opcode::Bem);
}

TEST_CASE("tokensFromBinary", "[decoder]") {
    Diagnostics diags;
    const uint32_t file = diags.addFile("x.bin");
    SECTION("little endian") {
        const std::string bytes("\x01\x01\xff\xff\xff\xff\x00\x00", 8);
        const auto tokens = tokensFromBinary(bytes, file, diags);
        REQUIRE(tokens);
        CHECK(*tokens == std::vector<uint32_t>{kPs11, kEnd});
    }
    SECTION("empty") {
        const auto tokens = tokensFromBinary("", file, diags);
        REQUIRE(tokens);
        CHECK(tokens->empty());
    }
    SECTION("odd size") {
        const std::string bytes("\x01\x01\xff\xff\xff\xff\x00", 7);
        CHECK_FALSE(tokensFromBinary(bytes, file, diags));
        REQUIRE(diags.all().size() == 1);
        const Diagnostic& d = diags.all()[0];
        CHECK(d.code == "P3001");
        CHECK(d.loc.tokenIndex == 1);
        CHECK(diags.format(d) == "x.bin: token 1: error P3001: binary size 7 bytes is not a multiple of 4 "
                                 "(3 trailing bytes: ff ff 00)");
    }
}

TEST_CASE("tokensFromHex", "[decoder]") {
    Diagnostics diags;
    const uint32_t file = diags.addFile("x.hex");
    SECTION("separators, prefixes and comments") {
        const auto tokens = tokensFromHex("0xFFFF0101, 00000042 ; tex\n b00f0000,0x0000ffff // end\n"
                                          "# whole line\n\t0X1//c\n2;c\n3#c\r\n",
                                          file, diags);
        INFO(diags.formatAll());
        REQUIRE(tokens);
        CHECK(*tokens == std::vector<uint32_t>{kPs11, 0x42, 0xB00F0000, kEnd, 1, 2, 3});
    }
    SECTION("bad words with line and column") {
        const auto tokens = tokensFromHex("0xffff0101\n  0x12g4, 0x\n123456789 /x\n", file, diags);
        CHECK_FALSE(tokens);
        INFO(diags.formatAll());
        REQUIRE(diags.errorCount() == 4);
        const auto& all = diags.all();
        CHECK(all[0].code == "P3002");
        CHECK(diags.format(all[0]) == "x.hex:2:3: error P3002: bad hex word '0x12g4' (expected up to 8 hex digits, "
                                      "optional 0x)");
        CHECK(all[1].loc.line == 2);
        CHECK(all[1].loc.col == 11);
        CHECK(all[2].loc.line == 3);
        CHECK(all[2].loc.col == 1);
        CHECK(all[3].loc.col == 11);
        CHECK(all[0].loc.tokenIndex == -1);
    }
    SECTION("a huge bad word is quoted as a short excerpt") {
        const std::string huge = "0x" + std::string(1 << 20, 'g');
        CHECK_FALSE(tokensFromHex("0xffff0101 " + huge + "\n", file, diags));
        REQUIRE(diags.errorCount() == 1);
        const std::string text = diags.format(diags.all()[0]);
        CHECK(text.rfind("x.hex:1:12: error P3002: bad hex word '0xggg", 0) == 0);
        CHECK(text.find("…'") != std::string::npos);
        CHECK(text.size() < 200);
    }
    SECTION("leading zeros beyond 8 digits are fine") {
        const auto tokens = tokensFromHex("000000000042", file, diags);
        REQUIRE(tokens);
        CHECK(*tokens == std::vector<uint32_t>{0x42});
    }
}

TEST_CASE("decoder: hex text through decode and disassemble", "[decoder]") {
    Diagnostics diags;
    const uint32_t file = diags.addFile("t.hex");
    const auto tokens = tokensFromHex("FFFF0101 00000042 B00F0000 00000002 80070000 80E40000 80E40001\n"
                                      "40000001 80080000 B0E40000 0000FFFF\n",
                                      file, diags);
    REQUIRE(tokens);
    const auto program = decode(*tokens, file, diags);
    REQUIRE(program);
    CHECK(disassemble(*program) == "ps_1_1\ntex t0\nadd r0.rgb, r0, r1\n+mov r0.a, t0\n");
}
