// Unit tests of the assembler front end and the encoder: every syntax form an author
// writes, checked against the token words native D3DAssemble emits (ps1x-spec.md §5.6,
// §5.7), and every syntax error with its code and place.
#include <catch2/catch.hpp>

#include <cstdio>
#include <string>

#include "ps11/assembler.h"
#include "ps11/encoder.h"

using namespace ps11;

namespace {

// Assembles text; returns the tokens as "ffff0101 00000042 …" or "ERR: <diagnostics>".
std::string hexOf(const std::string& text, const AssembleOptions& options = {}) {
    Diagnostics diags;
    std::optional<Program> prog = parseAssembly(text, "t.psh", options, diags);
    if (!prog) return "ERR: " + diags.formatAll();
    std::string out;
    char buf[12];
    for (uint32_t t : encode(*prog)) {
        std::snprintf(buf, sizeof buf, "%08x", t);
        if (!out.empty()) out += ' ';
        out += buf;
    }
    return out;
}

// Assembles text that must fail; returns the formatted diagnostics.
std::string errorsOf(const std::string& text) {
    Diagnostics diags;
    std::optional<Program> prog = parseAssembly(text, "t.psh", {}, diags);
    CHECK_FALSE(prog.has_value());
    return diags.formatAll();
}

}  // namespace

TEST_CASE("assembler: native reference encodings", "[assembler]") {
    CHECK(hexOf("ps.1.1\ntex t0\nadd r0.rgb, r0, r1\n+mov r0.a, t0\n") ==
          "ffff0101 00000042 b00f0000 00000002 80070000 80e40000 80e40001 40000001 80080000 b0e40000 0000ffff");
    CHECK(hexOf("ps_1_1\nmov_d4 r0, r1\n") == "ffff0101 00000001 8e0f0000 80e40001 0000ffff");
    CHECK(hexOf("ps_1_1\ndef c2, 0, 0., 0, 0.\n") ==
          "ffff0101 00000051 a00f0002 00000000 00000000 00000000 00000000 0000ffff");
    CHECK(hexOf("ps_1_3\ntexreg2ar t1, t0\n") == "ffff0103 00000045 b00f0001 b0e40000 0000ffff");
    CHECK(hexOf("ps_1_3\ntexm3x3spec t3, t0, c0\n") == "ffff0103 0000004c b00f0003 b0e40000 a0e40000 0000ffff");
    CHECK(hexOf("ps_1_3\nmov_x2_sat r0, 1 - r1\n") == "ffff0103 00000001 811f0000 86e40001 0000ffff");
    CHECK(hexOf("ps_1_3\nmov_x4_sat r0.a, -r1_bx2.a\n") == "ffff0103 00000001 82180000 85ff0001 0000ffff");
    CHECK(hexOf("ps_1_4\nbem r1.rg, c0, r0\n") == "ffff0104 00000059 80030001 a0e40000 80e40000 0000ffff");
    CHECK(hexOf("ps_1_4\nadd r0.rgb, r1, r2\n+add r0.a, r1, r2\n") ==
          "ffff0104 00000002 80070000 80e40001 80e40002 40000002 80080000 80e40001 80e40002 0000ffff");
    CHECK(hexOf("ps_1_4\ntexld r0, t0\n") == "ffff0104 00000042 800f0000 b0e40000 0000ffff");
    CHECK(hexOf("ps_1_4\ntexcrd r0, t0\n") == "ffff0104 00000040 800f0000 b0e40000 0000ffff");
    CHECK(hexOf("ps_1_4\ntexld r5, r2_dz\n") == "ffff0104 00000042 800f0005 89e40002 0000ffff");
    CHECK(hexOf("ps_1_4\ntexdepth r5\n") == "ffff0104 00000057 800f0005 0000ffff");
    CHECK(hexOf("ps_1_4\nphase\n") == "ffff0104 0000fffd 0000ffff");
    CHECK(hexOf("ps_1_1\ntexcoord t0\ntexkill t1\n") == "ffff0101 00000040 b00f0000 00000041 b00f0001 0000ffff");
}

TEST_CASE("assembler: headers, case, comments, line ends", "[assembler]") {
    const std::string expected = "ffff0102 00000001 800f0000 90e40000 0000ffff";
    CHECK(hexOf("ps_1_2\nmov r0, v0\n") == expected);
    CHECK(hexOf("ps.1.2\nmov r0, v0\n") == expected);
    CHECK(hexOf("PS_1_2\nMOV R0, V0\n") == expected);
    CHECK(hexOf("Ps.1.2\r\nMov r0 , v0\r\n") == expected);
    CHECK(hexOf("; header comment\nps_1_2 ; version\nmov r0, v0 ; copy\n") == expected);
    CHECK(hexOf("// header comment\nps_1_2 // version\nmov r0, v0 // copy\n") == expected);
    CHECK(hexOf("/* block\n comment */ ps_1_2\nmov /* inline */ r0, v0\n") == expected);
    CHECK(hexOf("ps_1_2\nmov r0, v0;\n") == expected);
    CHECK(hexOf("\n\n   ps_1_2\n\n\tmov\tr0,v0\n") == expected);
    CHECK(hexOf("ps_1_2\nmov r0, v0") == expected);  // no final newline
}

TEST_CASE("assembler: masks and selectors", "[assembler]") {
    CHECK(hexOf("ps_1_1\nmov r0.xyz, v0\n") == hexOf("ps_1_1\nmov r0.rgb, v0\n"));
    CHECK(hexOf("ps_1_1\nmov r0.w, v0\n") == "ffff0101 00000001 80080000 90e40000 0000ffff");
    CHECK(hexOf("ps_1_1\nmov r0.rgba, v0\n") == "ffff0101 00000001 800f0000 90e40000 0000ffff");
    CHECK(hexOf("ps_1_4\nmov r0.rba, v0\n") == "ffff0104 00000001 800d0000 90e40000 0000ffff");
    // Replicate selectors and partial selectors repeat their last letter.
    CHECK(hexOf("ps_1_1\nmov r0.a, v0.b\n") == "ffff0101 00000001 80080000 90aa0000 0000ffff");
    CHECK(hexOf("ps_1_1\nmov r0, v0.a\n") == "ffff0101 00000001 800f0000 90ff0000 0000ffff");
    CHECK(hexOf("ps_1_4\nmov r0, v0.r\n") == "ffff0104 00000001 800f0000 90000000 0000ffff");
    CHECK(hexOf("ps_1_4\nmov r0, v0.g\n") == "ffff0104 00000001 800f0000 90550000 0000ffff");
    CHECK(hexOf("ps_1_4\ntexld r0, t0.xyz\n") == "ffff0104 00000042 800f0000 b0a40000 0000ffff");
    CHECK(hexOf("ps_1_4\ntexcrd r1.rg, t0_dw.xyw\n") == "ffff0104 00000040 80030001 baf40000 0000ffff");
    CHECK(hexOf("ps_1_4\ntexcrd r1.rgb, t0.xyw\n") == "ffff0104 00000040 80070001 b0f40000 0000ffff");
    CHECK(hexOf("ps_1_4\ntexld r1, r0_db\n") == hexOf("ps_1_4\ntexld r1, r0_dz\n"));
    CHECK(hexOf("ps_1_4\ntexld r1, t0_da.xyw\n") == hexOf("ps_1_4\ntexld r1, t0_dw.xyw\n"));
}

TEST_CASE("assembler: source and instruction modifiers", "[assembler]") {
    auto src = [](const std::string& s) {
        std::string h = hexOf("ps_1_4\nmov r0, " + s + "\n");
        return h.size() >= 35 ? h.substr(27, 8) : h;
    };
    CHECK(src("r1") == "80e40001");
    CHECK(src("-r1") == "81e40001");
    CHECK(src("r1_bias") == "82e40001");
    CHECK(src("-r1_bias") == "83e40001");
    CHECK(src("r1_bx2") == "84e40001");
    CHECK(src("-r1_bx2") == "85e40001");
    CHECK(src("1-r1") == "86e40001");
    CHECK(src("1 - r1") == "86e40001");
    CHECK(src("r1_x2") == "87e40001");
    CHECK(src("-r1_x2") == "88e40001");
    CHECK(src("-r1_bx2.a") == "85ff0001");
    CHECK(src("-r1.a_bx2") == "85ff0001");  // selector before the modifier is accepted too
    auto dst = [](const std::string& m) {
        std::string h = hexOf("ps_1_4\nmov" + m + " r0, r1\n");
        return h.size() >= 26 ? h.substr(18, 8) : h;
    };
    CHECK(dst("") == "800f0000");
    CHECK(dst("_x2") == "810f0000");
    CHECK(dst("_x4") == "820f0000");
    CHECK(dst("_x8") == "830f0000");
    CHECK(dst("_d2") == "8f0f0000");
    CHECK(dst("_d4") == "8e0f0000");
    CHECK(dst("_d8") == "8d0f0000");
    CHECK(dst("_sat") == "801f0000");
    CHECK(dst("_x2_sat") == "811f0000");
    CHECK(dst("_sat_x2") == "811f0000");
    CHECK(dst("_X4_SAT") == "821f0000");
}

TEST_CASE("assembler: def literals", "[assembler]") {
    auto words = [](const std::string& v) {
        std::string h = hexOf("ps_1_1\ndef c0, " + v + "\n");
        return h.size() > 27 ? h.substr(27, 35) : h;
    };
    CHECK(words("1, 0.5, .25, -1") == "3f800000 3f000000 3e800000 bf800000");
    CHECK(words("1.0f, .5f, 0.25F, -1.f") == "3f800000 3f000000 3e800000 bf800000");
    CHECK(words("1e-1, 2.5E+1, -0, +3") == "3dcccccd 41c80000 80000000 40400000");
    CHECK(words("bits(0x7fc00000), bits(7f800000), 0, 0") == "7fc00000 7f800000 00000000 00000000");
    CHECK(words("0.1, 0.2, 0.3, 0.7") == "3dcccccd 3e4ccccd 3e99999a 3f333333");
}

TEST_CASE("assembler: co-issue styles", "[assembler]") {
    const std::string expected =
        "ffff0101 00000005 80070000 80e40000 90e40000 40000001 80080000 90e40000 0000ffff";
    CHECK(hexOf("ps_1_1\nmul r0.rgb, r0, v0\n+mov r0.a, v0\n") == expected);
    CHECK(hexOf("ps_1_1\nmul r0.rgb, r0, v0\n+ mov r0.a, v0\n") == expected);
    CHECK(hexOf("ps_1_1\nmul r0.rgb, r0, v0 +\nmov r0.a, v0\n") == expected);
    CHECK(hexOf("ps_1_1\nmul r0.rgb, r0, v0 + ; pair\nmov r0.a, v0\n") == expected);
    CHECK(hexOf("ps_1_1\nmul r0.rgb, r0, v0\n+\nmov r0.a, v0\n") == expected);
}

TEST_CASE("assembler: preprocessor drives the text", "[assembler]") {
    AssembleOptions options;
    options.preprocess.defines.emplace_back("USE_V1", "1");
    std::string text =
        "ps_1_1\n"
        "#define SRC(n) v##n\n"
        "#ifdef USE_V1\n"
        "mov r0, v1\n"
        "#else\n"
        "mov r0, v0\n"
        "#endif\n";
    CHECK(hexOf(text, options) == "ffff0101 00000001 800f0000 90e40001 0000ffff");
    CHECK(hexOf(text) == "ffff0101 00000001 800f0000 90e40000 0000ffff");
    CHECK(hexOf("#define OUT r0\n#define SCALE(x) x##_x2\nps_1_1\nmov OUT, v0\n") ==
          "ffff0101 00000001 800f0000 90e40000 0000ffff");
}

TEST_CASE("assembler: syntax errors name code, line and column", "[assembler]") {
    CHECK(errorsOf("mov r0, v0\n").find("t.psh:1:1: error P1101:") != std::string::npos);
    CHECK(errorsOf("").find("error P1101:") != std::string::npos);
    CHECK(errorsOf("ps_2_0\nmov r0, v0\n").find("t.psh:1:1: error P1102:") != std::string::npos);
    CHECK(errorsOf("ps_1_0\n").find("P1102") != std::string::npos);
    CHECK(errorsOf("ps_1_x\n").find("P1102") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nps_1_1\n").find("t.psh:2:1: error P1113:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nfoo r0, v0\n").find("t.psh:2:1: error P1103: unknown instruction 'foo'") !=
          std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov_x3 r0, v0\n").find("t.psh:2:4: error P1104:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov_x2_x2 r0, v0\n").find("t.psh:2:7: error P1104:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov_sat_sat r0, v0\n").find("P1104") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0\n").find("t.psh:2:7: error P1105:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, v0, v1\n").find("t.psh:2:11: error P1105: 'mov' takes 2 operands, found 3") !=
          std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov\n").find("P1105") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov x0, v0\n").find("t.psh:2:5: error P1106:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, v\n").find("t.psh:2:9: error P1106:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, v99999\n").find("P1106") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0.q, v0\n").find("t.psh:2:8: error P1107:") != std::string::npos);
    CHECK(errorsOf("ps_1_4\nmov r0.ar, v0\n").find("P1107") != std::string::npos);
    CHECK(errorsOf("ps_1_4\nmov r0.rr, v0\n").find("P1107") != std::string::npos);
    CHECK(errorsOf("ps_1_4\nmov r0.rgz, v0\n").find("P1107") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, v0.rgbar\n").find("t.psh:2:12: error P1108:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, v0.q\n").find("P1108") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, v0_foo\n").find("t.psh:2:11: error P1109:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, -1-v0\n").find("P1109") != std::string::npos);
    CHECK(errorsOf("ps_1_4\ntexld r0, -r1_dz\n").find("P1109") != std::string::npos);
    CHECK(errorsOf("ps_1_1\ndef c0, 1, 2, x, 4\n").find("t.psh:2:15: error P1110:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\ndef c0, 1, 2, 3\n").find("P1105") != std::string::npos);
    CHECK(errorsOf("ps_1_1\ndef c0, 1.2.3, 2, 3, 4\n").find("P1110") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0 v0\n").find("t.psh:2:8: error P1111:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, v0 +\n").find("error P1112:") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov_sat r0_x2, v0\n").find("P1104") != std::string::npos);
}

TEST_CASE("assembler: every error is collected", "[assembler]") {
    Diagnostics diags;
    std::optional<Program> prog =
        parseAssembly("ps_1_1\nfoo r0\nmov r0, q1\nmov r0.k, v0\nmov r0, v0\nbar\n", "t.psh", {}, diags);
    CHECK_FALSE(prog);
    CHECK(diags.errorCount() == 4);
}

TEST_CASE("assembler: registers the version does not have (P1114)", "[assembler]") {
    // Microsoft's assembler refuses them even with validation off (Wine's d3dcompiler
    // tests/asm.c failure_test), so `ps11 asm --no-validate` does too.
    CHECK(errorsOf("ps_1_3\nmov r5, r0\n") ==
          "t.psh:2:5: error P1114: register 'r5' does not exist in ps_1_3 (r0-r1)\n");
    CHECK(errorsOf("ps_1_3\ntex t5\n") == "t.psh:2:5: error P1114: register 't5' does not exist in ps_1_3 (t0-t3)\n");
    // Every operand is checked, and parsing goes on after one.
    CHECK(errorsOf("ps_1_1\nmov r2, c8\n") ==
          "t.psh:2:5: error P1114: register 'r2' does not exist in ps_1_1 (r0-r1)\n"
          "t.psh:2:9: error P1114: register 'c8' does not exist in ps_1_1 (c0-c7)\n");
    CHECK(errorsOf("ps_1_2\ndef c8, 1, 1, 1, 1\n").find("t.psh:2:5: error P1114: register 'c8'") != std::string::npos);
    CHECK(errorsOf("ps_1_1\ntexkill t4\n").find("t.psh:2:9: error P1114: register 't4'") != std::string::npos);
    CHECK(errorsOf("ps_1_2\nmov r0, -v2_bx2.a\n").find("t.psh:2:10: error P1114: register 'v2'") != std::string::npos);
    CHECK(errorsOf("ps_1_4\nmov r6, v0\n").find("(r0-r5)") != std::string::npos);
    CHECK(errorsOf("ps_1_4\ntexld r0, t6\n")
              .find("t.psh:2:11: error P1114: register 't6' does not exist in "
                    "ps_1_4 (t0-t5)") != std::string::npos);
    CHECK(errorsOf("ps_1_4\nmov r0, v2\n").find("(v0-v1)") != std::string::npos);
    // The last register of each file exists; register types are the validator's (Wine's asm.c
    // ps_1_4 tests: "texld r1, t4" and "texld r5, c0" assemble without validation).
    CHECK(hexOf("ps_1_4\nmov r5, c7\n") == "ffff0104 00000001 800f0005 a0e40007 0000ffff");
    CHECK(hexOf("ps_1_4\ntexld r1, t4\n") == "ffff0104 00000042 800f0001 b0e40004 0000ffff");
    CHECK(hexOf("ps_1_4\ntexld r5, c0\n") == "ffff0104 00000042 800f0005 a0e40000 0000ffff");
    CHECK(hexOf("ps_1_1\nmov r1, v1\n+mov t3.a, c7\n").rfind("ffff0101", 0) == 0);
    // Without a valid version there is nothing to check against: only the version error.
    CHECK(errorsOf("mov r5, r0\n") ==
          "t.psh:1:1: error P1101: the shader must start with a version statement (ps_1_1 … ps_1_4)\n");
    CHECK(errorsOf("ps_2_0\nmov r5, r0\n").find("P1114") == std::string::npos);
}

TEST_CASE("assembler: Wine's failure_test cases for ps 1.x do not assemble", "[assembler]") {
    // dlls/d3dcompiler_43/tests/asm.c failure_test: D3DAssemble with D3DCOMPILE_SKIP_VALIDATION
    // returns D3DXERR_INVALIDDATA for each; here each is a syntax error with its code.
    CHECK(errorsOf("ps_1_3\nmov_x2_x2 r0, r1\n").find("t.psh:2:7: error P1104:") != std::string::npos);   // shader 8
    CHECK(errorsOf("ps_1_4\ntexld r5, -r2_dz\n").find("t.psh:2:11: error P1109:") != std::string::npos);  // 10
    CHECK(errorsOf("ps_1_3\nmov r5, r0\n").find("t.psh:2:5: error P1114:") != std::string::npos);         // 22
    CHECK(errorsOf("ps_1_3\nadd oC0, r0, r1\n").find("t.psh:2:5: error P1106:") != std::string::npos);    // 26
    CHECK(errorsOf("ps_1_3\ntex t5\n").find("t.psh:2:5: error P1114:") != std::string::npos);             // 32
    // What Wine's asmparser.c also refuses in ps 1.x at parse time: the _abs modifier and
    // relative addressing.
    CHECK(errorsOf("ps_1_4\nmov r0, r1_abs\n").find("P1109") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nmov r0, c[a0.x]\n").find("P1106") != std::string::npos);
}

TEST_CASE("assembler: an unknown instruction suggests the nearest one", "[assembler]") {
    CHECK(errorsOf("ps_1_1\nmull r0, v0, v1\n") ==
          "t.psh:2:1: error P1103: unknown instruction 'mull'; did you mean 'mul'?\n");
    CHECK(errorsOf("ps_1_1\nMOVV_sat r0, v0\n").find("unknown instruction 'MOVV'; did you mean 'mov'?") !=
          std::string::npos);
    // The version's own instructions first: texcoord in 1_1-1_3, texcrd in 1_4.
    CHECK(errorsOf("ps_1_2\ntexcord t0\n").find("did you mean 'texcoord'?") != std::string::npos);
    CHECK(errorsOf("ps_1_4\ntexcord r0, t0\n").find("did you mean 'texcrd'?") != std::string::npos);
    // Else any version's (bem is ps_1_4 only, and nothing of ps_1_1 is close to "bemm").
    CHECK(errorsOf("ps_1_1\nbemm r1, c0, r0\n").find("did you mean 'bem'?") != std::string::npos);
    CHECK(errorsOf("ps_1_1\ndpp4 r0, v0, v1\n").find("did you mean 'dp4'?") != std::string::npos);
    CHECK(errorsOf("ps_1_1\nfoo r0, v0\n") == "t.psh:2:1: error P1103: unknown instruction 'foo'\n");
    // Nothing close: no suggestion; the reserved texm3x3diff is never offered.
    CHECK(errorsOf("ps_1_1\nfrobnicate r0, v0\n").find("did you mean") == std::string::npos);
    CHECK(errorsOf("ps_1_1\ntexm3x3dif t1, t0\n").find("texm3x3diff'?") == std::string::npos);
}

TEST_CASE("assembler: diagnostics quote at most a short excerpt of a huge line", "[assembler]") {
    const std::string garbage(1 << 20, 'z');
    std::string e = errorsOf("ps_1_1 " + garbage + "\nmov r0, v0\n");
    CHECK(e.rfind("t.psh:1:8: error P1111: unexpected text after the version: 'zzz", 0) == 0);
    CHECK(e.find("…'") != std::string::npos);
    CHECK(e.size() < 200);
    // A 1 MB identifier as the instruction, as a register and as a modifier.
    e = errorsOf("ps_1_1\n" + garbage + " r0, v0\n");
    CHECK(e.rfind("t.psh:2:1: error P1103: unknown instruction 'zzz", 0) == 0);
    CHECK(e.size() < 200);
    e = errorsOf("ps_1_1\nmov r0, " + garbage + "\n");
    CHECK(e.rfind("t.psh:2:9: error P1106: 'zzz", 0) == 0);
    CHECK(e.size() < 200);
    e = errorsOf("ps_1_1\nmov r0, v0_" + garbage + "\n");
    CHECK(e.rfind("t.psh:2:11: error P1109:", 0) == 0);
    CHECK(e.size() < 200);
    e = errorsOf("ps_1_1\nmov r0, v0 " + garbage + "\n");
    CHECK(e.rfind("t.psh:2:12: error P1111:", 0) == 0);
    CHECK(e.size() < 200);
    e = errorsOf("ps_1_1\nmov r0, v0." + garbage + "\n");
    CHECK(e.rfind("t.psh:2:12: error P1108:", 0) == 0);
    CHECK(e.size() < 200);
}
