// Unit tests for the validator (ps11/validator.h): every rule family on assembled text, hand-built
// IR for what the assembler cannot produce, the statistics, and the tests/shaders/validate corpus
// (each file's expected code must be reported at its LINE:COL, and no other error unless listed).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/validator.h"

using namespace ps11;

namespace {

struct Checked {
    Diagnostics diags;
    ShaderStats stats;
    bool valid = false;
};

Checked check(const std::string& text, const ValidateOptions& options = {}) {
    Checked out;
    std::optional<Program> program = parseAssembly(text, "test.psh", {}, out.diags);
    INFO(out.diags.formatAll());
    REQUIRE(program.has_value());
    out.valid = validate(*program, out.diags, &out.stats, options);
    return out;
}

std::vector<std::string> errorCodes(const Diagnostics& diags) {
    std::vector<std::string> codes;
    for (const Diagnostic& d : diags.all())
        if (d.severity == Severity::Error) codes.push_back(d.code);
    return codes;
}

const Diagnostic* findError(const Diagnostics& diags, const std::string& code) {
    for (const Diagnostic& d : diags.all())
        if (d.severity == Severity::Error && d.code == code) return &d;
    return nullptr;
}

// Exactly one error, with this code, at line:col (col 0 = any).
void expectOnly(const std::string& text, const std::string& code, uint32_t line, uint32_t col) {
    Checked c = check(text);
    INFO(text);
    INFO(c.diags.formatAll());
    REQUIRE(errorCodes(c.diags) == std::vector<std::string>{code});
    const Diagnostic* d = findError(c.diags, code);
    CHECK(d->loc.line == line);
    if (col) CHECK(d->loc.col == col);
    CHECK_FALSE(c.valid);
}

void expectValid(const std::string& text) {
    Checked c = check(text);
    INFO(text);
    INFO(c.diags.formatAll());
    CHECK(c.valid);
    CHECK(errorCodes(c.diags).empty());
}

// Hand-built IR for cases the assembler rejects or cannot spell.
Instruction makeInst(std::string_view mnemonic, int minor) {
    Instruction in;
    in.info = findOpcode(mnemonic, minor);
    REQUIRE(in.info != nullptr);
    in.loc.line = 2;
    in.loc.col = 1;
    return in;
}

Src makeSrc(RegType t, uint8_t index) {
    Src s;
    s.type = t;
    s.index = index;
    return s;
}

}  // namespace

TEST_CASE("validator: version legality", "[validator]") {
    expectOnly("ps_1_1\ndp4 r0, v0, v1\nmov r0, v0\n", "P2002", 2, 1);
    expectOnly("ps_1_1\ncmp r0, v0, v1, c0\nmov r0, v0\n", "P2002", 2, 1);
    expectOnly("ps_1_4\ntex t0\nmov r0, v0\n", "P2002", 2, 1);
    expectOnly("ps_1_2\nbem r0.rg, v0, v1\nmov r0, v0\n", "P2002", 2, 1);
    expectOnly("ps_1_1\ntex t0\ntexm3x3diff t1, t0\nmov r0, t0\n", "P2003", 3, 1);
    Checked c = check("ps_1_4\ntexcoord t0\nmov r0, v0\n");
    REQUIRE(findError(c.diags, "P2002"));
    CHECK(findError(c.diags, "P2002")->message.find("uses texcrd") != std::string::npos);
    expectValid("ps_1_1\ntex t0\ntexreg2gb t1, t0\nmov r0, t1\n");  // spec §7.10: texreg2gb in ps_1_1

    Program p;
    p.version = {2, 0};
    p.versionLoc.line = 1;
    Diagnostics d;
    CHECK_FALSE(validate(p, d));
    CHECK(errorCodes(d) == std::vector<std::string>{"P2001"});
    p.version = {1, 0};
    d.clear();
    CHECK_FALSE(validate(p, d));
    CHECK(d.has("P2001"));
}

TEST_CASE("validator: slot limits", "[validator]") {
    std::string eight = "ps_1_1\n";
    for (int i = 0; i < 8; ++i) eight += "mov r0, v0\n";
    expectValid(eight);
    Checked c = check(eight + "mov r0, v1\nmov r0, v1\n");
    REQUIRE(errorCodes(c.diags) == std::vector<std::string>{"P2011"});  // reported once
    CHECK(findError(c.diags, "P2011")->loc.line == 10);
    CHECK(findError(c.diags, "P2011")->message == "ps_1_1 allows 8 arithmetic slots; this instruction makes 9");
    CHECK(c.stats.arithSlots == 10);

    // dp4 costs 2 in 1_2, 1 in 1_4.
    Checked d = check("ps_1_2\ndp4 r0, v0, v1\n");
    CHECK(d.stats.arithSlots == 2);
    CHECK(d.stats.table[0].arithSlots == 2);
    Checked e = check("ps_1_4\ndp4 r0, v0, v1\n");
    CHECK(e.stats.arithSlots == 1);
    // texbeml: 1 T + 1 A; bem 2 A; pair 1; nop 0.
    Checked f = check("ps_1_1\ntex t0\ntexbeml t1, t0\nmov r0.rgb, t1\n+mov r0.a, t1\nnop\n");
    CHECK(f.valid);
    CHECK(f.stats.texSlots == 2);
    CHECK(f.stats.arithSlots == 2);
    CHECK(f.stats.table[3].arithSlots == 0);
    CHECK(f.stats.table[4].arithSlots == 0);
    Checked g = check("ps_1_4\ntexld r0, t0\ntexcrd r1.rgb, t1\nbem r1.rg, r1, r0\nphase\ntexld r1, r1\nmov r0, r1\n");
    CHECK(g.valid);
    CHECK(g.stats.phaseArithSlots[0] == 2);
    CHECK(g.stats.phaseArithSlots[1] == 1);
    CHECK(g.stats.phaseTexSlots[0] == 2);
    CHECK(g.stats.phaseTexSlots[1] == 1);
    // Per-shader caps only where the instruction costs 2 slots.
    expectOnly("ps_1_3\ncmp r0, v0, v1, c0\ncmp r0, v0, v1, c0\ncmp r0, v0, v1, c0\ncmp r0, v0, v1, c0\n", "P2012", 5,
               1);
    // ps_1_4 per phase: 6 texture instructions per phase, 12 in the shader is fine.
    std::string t14 = "ps_1_4\n";
    for (int i = 0; i < 6; ++i) t14 += "texld r" + std::to_string(i) + ", t" + std::to_string(i) + "\n";
    t14 += "phase\n";
    for (int i = 0; i < 6; ++i) t14 += "texld r" + std::to_string(i) + ", t" + std::to_string(i) + "\n";
    expectValid(t14 + "mov r0, r1\n");
}

TEST_CASE("validator: ordering", "[validator]") {
    expectOnly("ps_1_1\ntex t0\ndef c0, 1, 1, 1, 1\nmov r0, t0\n", "P2020", 3, 1);
    expectOnly("ps_1_1\nmov r0, v0\ntex t0\n", "P2021", 3, 1);
    expectValid("ps_1_1\nnop\ntex t0\nmov r0, t0\n");  // nop is neutral
    expectOnly("ps_1_4\ntexld r0, t0\nmov r1, r0\ntexld r2, t2\nphase\nmov r0.rgb, r1.b\n+mov r0.a, c0\n", "P2022", 4,
               1);
    expectOnly("ps_1_4\ntexld r0, t0\nphase\ntexld r1, t1\nphase\nmov r0, c0\n", "P2023", 5, 1);
    // Phase 2 starts a new texture block.
    expectValid("ps_1_4\ntexld r0, t0\nmov r1, r0\nphase\ntexld r2, t2\nmov r0, r2\n");
}

TEST_CASE("validator: registers the version lacks, in decoded tokens (P2030)", "[validator]") {
    // The assembler refuses these already (P1114); a token stream reaches the validator with them.
    auto decodedErrors = [](std::vector<uint32_t> tokens) {
        Diagnostics diags;
        std::optional<Program> program = decode(tokens, diags.addFile("t.bin"), diags);
        INFO(diags.formatAll());
        REQUIRE(program.has_value());
        CHECK_FALSE(validate(*program, diags));
        INFO(diags.formatAll());
        return errorCodes(diags);
    };
    // ps_1_1: mov r2, v0 / mov r0, v0
    CHECK(decodedErrors({0xffff0101, 0x00000001, 0x800f0002, 0x90e40000, 0x00000001, 0x800f0000, 0x90e40000,
                         0x0000ffff}) == std::vector<std::string>{"P2030"});
    // ps_1_3: mov r5, r0 (Wine's failure_test shader 22, here as tokens); r0 is also never written.
    std::vector<std::string> codes = decodedErrors({0xffff0103, 0x00000001, 0x800f0005, 0x80e40000, 0x0000ffff});
    CHECK(std::find(codes.begin(), codes.end(), "P2030") != codes.end());
    // ps_1_4: mov r0, r6
    codes = decodedErrors({0xffff0104, 0x00000001, 0x800f0000, 0x80e40006, 0x0000ffff});
    CHECK(std::find(codes.begin(), codes.end(), "P2030") != codes.end());
}

TEST_CASE("validator: registers", "[validator]") {
    expectValid("ps_1_4\nmov r5, c7\nmov r0, r5\n");
    expectOnly("ps_1_1\nmov v0, v1\nmov r0, v0\n", "P2031", 2, 5);
    expectOnly("ps_1_4\nmov t0, v0\nmov r0, v0\n", "P2031", 2, 5);
    expectOnly("ps_1_1\ntex t0\ntexbem t1, c0\nmov r0, t1\n", "P2032", 3, 12);
    expectOnly("ps_1_4\nmov r0, t0\n", "P2033", 2, 9);
    expectOnly("ps_1_4\nmov r0, v0\nphase\nmov r0, v0\n", "P2034", 2, 9);
    expectValid("ps_1_4\ntexkill t0\nmov r0, v0\n");
    expectValid("ps_1_4\ntexcrd r1.rgb, t0\ntexkill r1\nmov r0, v0\n");
}

TEST_CASE("validator: read ports", "[validator]") {
    expectOnly("ps_1_1\nmad r0, c0, c1, c2\n", "P2040", 2, 17);
    expectValid("ps_1_1\nmad r0, c0, c1, c0\n");
    expectOnly("ps_1_1\ntex t0\ntex t1\ntex t2\nmad r0, t0, t1, t2\n", "P2040", 5, 17);
    expectValid("ps_1_3\ntex t0\ntex t1\ntex t2\nmad r0, t0, t1, t2\n");
    Checked c = check("ps_1_1\nmul r0.rgb, c0, c1\n+mul r0.a, c2, c3\n");
    REQUIRE(errorCodes(c.diags) == std::vector<std::string>{"P2041"});
    CHECK(findError(c.diags, "P2041")->loc.line == 3);
    CHECK(findError(c.diags, "P2041")->message.find("c0, c1, c2, c3") != std::string::npos);
    Checked ok = check("ps_1_1\nmul r0.rgb, c0, c1\n+mul r0.a, c2, c1\n");
    CHECK(ok.valid);
    CHECK(ok.stats.maxPairReadPorts[size_t(RegType::Const)] == 3);
    CHECK(ok.stats.maxReadPorts[size_t(RegType::Const)] == 2);
    CHECK(ok.stats.readPortLimit == std::array<int, 4>{2, 2, 2, 2});
    CHECK(check("ps_1_4\nmov r0, v0\n").stats.readPortLimit == std::array<int, 4>{3, 2, 2, 1});
    CHECK(check("ps_1_2\nmov r0, v0\n").stats.readPortLimit == std::array<int, 4>{2, 2, 2, 3});
}

TEST_CASE("validator: write masks", "[validator]") {
    expectOnly("ps_1_1\nmov r0.rg, v0\nmov r0, v0\n", "P2050", 2, 5);
    expectOnly("ps_1_1\nmov r0, v0\ndp3 r0.a, v0, v1\n", "P2051", 3, 5);
    expectValid("ps_1_1\ndp3 r0.rgb, v0, v1\nmov r0.a, v0\ndp3 r1, v0, v1\n");
    expectValid("ps_1_4\nmov r0.rb, v0\nmov r0.ga, v1\n");
    expectOnly("ps_1_1\ntex t0.rgb\nmov r0, t0\n", "P2052", 2, 5);
    expectOnly("ps_1_4\ntexld r0.rgb, t0\nmov r0.a, c0\n", "P2053", 2, 7);
    expectValid("ps_1_4\ntexcrd r0.rg, t0\ntexcrd r1.rgb, t1\ntexcrd r2, t2\nmov r0, c0\n");
    expectOnly("ps_1_4\ntexld r0, t0\nbem r1.r, c0, r0\nphase\nmov r0, c0\n", "P2053", 3, 5);

    // Empty mask (the assembler can't spell it).
    Program p;
    p.version = {1, 4};
    Instruction mov = makeInst("mov", 4);
    mov.dst.mask = 0;
    mov.dst.loc = {0, 2, 5, -1};
    mov.src[0] = makeSrc(RegType::Input, 0);
    Instruction mov2 = makeInst("mov", 4);
    mov2.src[0] = makeSrc(RegType::Input, 0);
    p.instructions = {mov, mov2};
    Diagnostics d;
    validate(p, d);
    CHECK(errorCodes(d) == std::vector<std::string>{"P2050"});
}

TEST_CASE("validator: selectors", "[validator]") {
    expectOnly("ps_1_1\nmov r0, v0.g\n", "P2060", 2, 9);
    expectOnly("ps_1_4\nmov r0, v0.xyz\n", "P2060", 2, 9);
    expectValid("ps_1_4\nmov r0, v0.r\nmov r1, v0.g\nadd r0, r0, r1.b\n");
    // Spec §3.4: .b replicate only when the instruction's write mask is .a.
    expectValid("ps_1_1\nmov r0.a, v0.b\nmov r0.rgb, v0.a\n");
    expectOnly("ps_1_1\nmov r0, v0.b\n", "P2061", 2, 9);
    expectOnly("ps_1_2\nmov r0.a, v0\nmov r0.rgb, v0.b\n", "P2061", 3, 13);
    expectOnly("ps_1_1\ntex t0\ntexreg2ar t1, t0.a\nmov r0, t1\n", "P2062", 3, 15);
    expectOnly("ps_1_4\ntexld r0, t0_dw.xyz\n", "P2063", 2, 11);
    expectOnly("ps_1_4\ntexld r0, t0_dz\n", "P2063", 2, 11);
    expectValid("ps_1_4\ntexld r0, t0_dw.xyw\ntexcrd r1.rg, t1_dw.xyw\nmul r0, r0, r1.r\n");
    expectValid("ps_1_4\ntexcrd r0.rgb, t0\nphase\ntexld r1, r0_dz.xyz\ntexld r2, r0_dz\nmul r0, r1, r2\n");
    expectOnly(
        "ps_1_4\ntexcrd r0.rgb, t0\ntexcrd r1.rgb, t1\ntexcrd r2.rgb, t2\nphase\ntexld r3, r0_dz\n"
        "texld r4, r1_dz\ntexld r5, r2_dz\nmul r0, r3, r4\n",
        "P2064", 8, 11);
    expectOnly("ps_1_4\ntexld r0, t0\ntexcrd r1.rgb, t0.xyw\nmul r0, r0, r1.r\n", "P2065", 3, 16);
}

TEST_CASE("validator: modifiers", "[validator]") {
    expectOnly("ps_1_1\nmov r0, v0_x2\n", "P2070", 2, 9);
    expectValid("ps_1_4\nmov r0, -v0_x2\n");
    expectOnly("ps_1_4\nmov r0, v0_dz\n", "P2070", 2, 9);
    expectOnly("ps_1_4\nmov r0, 1-c0\n", "P2071", 2, 9);
    // 1_1-1_3: a warning only.
    Checked w = check("ps_1_1\nmov r0, -c0\n");
    CHECK(w.valid);
    REQUIRE(w.diags.all().size() == 1);
    CHECK(w.diags.all()[0].severity == Severity::Warning);
    CHECK(w.diags.all()[0].code == "P2072");
    expectOnly("ps_1_1\ntex t0\ntexbem t1, t0_bx2\nmov r0, t1\n", "P2073", 3, 12);
    expectValid("ps_1_2\ntex t0\ntexdp3 t1, t0_bx2\nmov r0, t1\n");
    expectValid("ps_1_1\ntex t0\ntexm3x2pad t1, t0_bx2\ntexm3x2tex t2, t0_bx2\nmov r0, t2\n");
    expectOnly("ps_1_1\nmov_x8 r0, v0\n", "P2074", 2, 1);
    expectValid("ps_1_1\nmov_x4_sat r0, v0\nmov_d2 r0, r0\n");
    expectValid("ps_1_4\nmov_x8 r0, v0\nmov_d8_sat r0, r0\n");
    expectOnly("ps_1_1\ntex_x2 t0\nmov r0, t0\n", "P2075", 2, 1);
    expectOnly("ps_1_4\ntexcrd_sat r0, t0\nmov r0, c0\n", "P2075", 2, 1);
}

TEST_CASE("validator: co-issue", "[validator]") {
    expectValid("ps_1_1\nmov r0.rgb, v0\n+mov r0.a, v1\n");
    expectValid("ps_1_1\nmov r0.a, v0\n+dp3 r0.rgb, v0, v1\n");
    expectValid("ps_1_4\nmov r0.rg, v0\n+mov r0.a, v1\nmov r0.b, v1\n");
    expectOnly("ps_1_1\n+mov r0.a, v0\nmov r0.rgb, v0\n", "P2080", 2, 2);
    expectOnly("ps_1_1\ntex t0\n+mov r0.a, t0\nmov r0.rgb, t0\n", "P2080", 3, 2);
    expectOnly("ps_1_1\nmov r0.rgb, v0\n+mov r0.a, v0\n+mov r1.a, v0\n", "P2080", 4, 2);
    expectOnly("ps_1_2\ndp4 r0.rgb, v0, v1\n+mov r0.a, v0\n", "P2081", 3, 2);
    expectOnly("ps_1_1\nmov r0.rgb, v0\n+nop\nmov r0.a, v0\n", "P2081", 3, 2);
    expectOnly("ps_1_1\nmov r0, v0\n+mov r1.a, v0\n", "P2082", 3, 2);
    expectOnly("ps_1_1\nmov r0.rgb, v0\n+mov r1.rgb, v0\nmov r0.a, v0\n", "P2082", 3, 2);
    expectOnly("ps_1_4\nmov r0.rgb, v0\n+dp3 r0.a, v0, v1\n", "P2083", 3, 2);
}

TEST_CASE("validator: read before write", "[validator]") {
    expectOnly("ps_1_1\nmov r0, r1\n", "P2090", 2, 9);
    Checked c = check("ps_1_1\nmov r1.rgb, v0\nmov r0, r1\n");
    REQUIRE(errorCodes(c.diags) == std::vector<std::string>{"P2090"});
    CHECK(findError(c.diags, "P2090")->message.find("r1.a") == 0);
    expectValid("ps_1_1\nmov r1.rgb, v0\nmov r0.rgb, r1\n+mov r0.a, v0\n");
    // .a selector reads alpha for every channel.
    expectOnly("ps_1_1\nmov r1.rgb, v0\nmov r0, r1.a\n", "P2090", 3, 9);
    // dp3 reads rgb only, even with an .rgba mask.
    expectValid("ps_1_1\nmov r1.rgb, v0\ndp3 r0, r1, v0\n");
    // Co-issued members read old values.
    expectOnly("ps_1_1\nmov r0.rgb, v0\n+mov r0.a, r0.b\n", "P2090", 3, 12);
    expectValid("ps_1_1\nmov r0, v0\nmov r0.rgb, r0.a\n+mov r0.a, r0.b\n");
    // texkill / pad destinations stay undefined.
    Checked k = check("ps_1_1\ntexkill t0\nmov r0, t0\n");
    REQUIRE(findError(k.diags, "P2090"));
    CHECK(findError(k.diags, "P2090")->message.find("texkill") != std::string::npos);
    // Phase clears alpha; texcrd leaves .a (and .b with .rg) undefined.
    Checked ph = check("ps_1_4\nmov r1, c0\nphase\nmov r0, r1.a\n");
    REQUIRE(findError(ph.diags, "P2090"));
    CHECK(findError(ph.diags, "P2090")->message.find("phase") != std::string::npos);
    expectValid("ps_1_4\nmov r1, c0\nphase\nmov r0.rgb, r1.b\n+mov r0.a, c0\n");
    expectOnly("ps_1_4\ntexcrd r0.rg, t0\nmov r1, c0\nmov r0, r0.b\n", "P2090", 4, 9);
    expectOnly("ps_1_4\ntexcrd r0.rgb, t0_dw.xyw\nmov r0, r0.b\n", "P2090", 3, 9);
    // r0.
    expectOnly("ps_1_1\ntex t0\nmov r1, t0\n", "P2091", 1, 1);
    Checked none = check("ps_1_1\ntex t0\nmov r1, t0\n", ValidateOptions{false});
    CHECK(none.valid);
    expectOnly("ps_1_4\ntexld r0, t0\nmov r0, r0\nphase\ntexld r1, t1\nmov r0.rgb, r1\n", "P2092", 4, 1);
    Checked part = check("ps_1_1\nmov r0.rgb, v0\n");
    CHECK(part.valid);
    REQUIRE(part.diags.all().size() == 1);
    CHECK(part.diags.all()[0].code == "P2093");
}

TEST_CASE("validator: texture sequences and special instructions", "[validator]") {
    expectOnly("ps_1_1\ntex t0\ntexm3x2pad t1, t0\nmov r0, t0\n", "P2100", 3, 1);
    expectOnly("ps_1_1\ntex t0\ntexm3x2pad t1, t0\ntexm3x2tex t3, t0\nmov r0, t3\n", "P2101", 4, 12);
    expectOnly("ps_1_1\ntex t0\ntex t1\ntexm3x2pad t2, t0\ntexm3x2tex t3, t1\nmov r0, t3\n", "P2102", 5, 16);
    expectOnly("ps_1_1\ntex t0\ntexm3x3tex t1, t0\nmov r0, t1\n", "P2103", 3, 1);
    expectValid("ps_1_1\ntex t0\ntexm3x3pad t1, t0\ntexm3x3pad t2, t0\ntexm3x3vspec t3, t0\nmov r0, t3\n");
    expectValid("ps_1_2\ntex t0\ntexm3x3pad t1, t0\ntexm3x3pad t2, t0\ntexm3x3 t3, t0\nmov r0, t3\n");
    expectOnly("ps_1_1\ntex t0\ntexbem t1, t0\nmul r0, t1, t0\n", "P2104", 4, 13);
    expectOnly("ps_1_1\ntex t0\ntexkill t0\nmov r0, t0\n", "P2105", 3, 9);
    expectOnly("ps_1_3\ntex t0\ntexm3x2pad t1, t0\ntexm3x2depth t2, t0\nmov r0, t2\n", "P2106", 5, 9);
    expectOnly("ps_1_1\ntex t1\ntexbem t0, t1\nmov r0, t0\n", "P2107", 3, 12);
    expectOnly("ps_1_1\nmov r1, v0\ncnd r0, r1.a, v0, v1\n", "P2108", 3, 9);
    expectValid("ps_1_1\nmov r0.a, v0\ncnd r0, r0.a, v0, v1\n");
    expectOnly("ps_1_2\nmov r0, v0\ncmp r0, r0, v0, v1\n", "P2109", 3, 9);
    expectValid("ps_1_4\nmov r0, v0\ncmp r0, r0, v0, r0\n");
    expectOnly("ps_1_4\ntexld r0, t0\nbem r1.rg, c0, r0\nmov r0, c0\n", "P2110", 3, 1);
    expectOnly("ps_1_4\ntexcrd r4.rgb, t0\nphase\ntexdepth r4\ntexld r0, t0\n", "P2111", 4, 10);
    expectOnly("ps_1_4\ntexcrd r5.rgb, t0\ntexdepth r5\nphase\ntexld r0, t0\n", "P2112", 3, 1);
    expectOnly("ps_1_4\ntexcrd r5.rgb, t0\nphase\ntexdepth r5\ntexld r0, t1\nmov r0, r5\n", "P2106", 6, 9);
}

TEST_CASE("validator: all errors are collected", "[validator]") {
    Checked c = check("ps_1_1\nmov v1, v0.g\ndp4 r0, v0, v1\nmov_x8 r0.rg, v0\n");
    std::vector<std::string> codes = errorCodes(c.diags);
    for (const char* code : {"P2031", "P2060", "P2002", "P2074", "P2050"})
        CHECK(std::find(codes.begin(), codes.end(), code) != codes.end());
}

TEST_CASE("validator: statistics text and JSON", "[validator]") {
    Checked c = check(
        "ps_1_4\ndef c1, 1, 0, 0, 1\ntexld r0, t0\nmul r1, r0, c0\nphase\ntexld r2, r1\n"
        "mul r0.rgb, r2, v0\n+mov r0.a, c1\n");
    REQUIRE(c.valid);
    const ShaderStats& s = c.stats;
    CHECK(s.version == Version{1, 4});
    CHECK(s.hasPhase);
    CHECK(s.texLimit == 6);
    CHECK(s.arithLimit == 8);
    CHECK(s.constantsRead == std::vector<int>{0, 1});
    CHECK(s.constantsDefined == std::vector<int>{1});
    REQUIRE(s.table.size() == 7);
    CHECK(s.table[0].text == "def c1, 1, 0, 0, 1");
    CHECK(s.table[6].text == "+mov r0.a, c1");
    CHECK(s.table[6].coissue);
    CHECK(s.table[1].phase == 1);
    CHECK(s.table[4].phase == 2);
    std::string text = statsToText(s);
    CHECK(text.find("phase 1: texture 1/6, arithmetic 1/8") != std::string::npos);
    CHECK(text.find("constants read: c0 c1") != std::string::npos);
    std::string json = statsToJson(s);
    INFO(json);
    CHECK(nlohmann::json::accept(json));
    CHECK(json.find("\"version\":\"ps_1_4\"") != std::string::npos);
    CHECK(json.find("\"text\":\"+mov r0.a, c1\"") != std::string::npos);

    // Stats are filled for invalid shaders too, and text with quotes/backslashes is escaped.
    Checked bad = check("ps_1_1\nmov r0, r1\n");
    CHECK_FALSE(bad.stats.valid);
    ShaderStats odd = bad.stats;
    odd.table[0].text = "a \"quoted\" \\ text\n\x01";
    REQUIRE(nlohmann::json::accept(statsToJson(odd)));
    CHECK(nlohmann::json::parse(statsToJson(odd))["instructions"][0]["text"] == odd.table[0].text);
    CHECK(statsToText(bad.stats).find("(invalid)") != std::string::npos);
}

TEST_CASE("validator: tests/shaders/validate corpus", "[validator][corpus]") {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(PS11_SOURCE_DIR) / "tests" / "shaders" / "validate";
    REQUIRE(fs::is_directory(dir));
    size_t files = 0, fails = 0;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
        if (entry.path().extension() != ".ps11test") continue;
        ++files;
        std::ifstream in(entry.path());
        std::vector<std::string> lines;
        for (std::string l; std::getline(in, l);) lines.push_back(l);
        std::vector<std::string> also;
        std::string code;
        uint32_t wantLine = 0, wantCol = 0;
        size_t header = lines.size();
        for (size_t i = 0; i < lines.size(); ++i) {
            if (lines[i].rfind("% also ", 0) == 0) {
                std::istringstream ss(lines[i].substr(7));
                for (std::string c; ss >> c;) also.push_back(c);
            }
            if (lines[i].rfind("[pixel shader", 0) == 0) {
                header = i;
                char buf[16] = {};
                if (std::sscanf(lines[i].c_str(), "[pixel shader fail %15s at %u:%u]", buf, &wantLine, &wantCol) >= 1)
                    code = buf;
                break;
            }
        }
        INFO(entry.path().string());
        REQUIRE(header < lines.size());
        // The block assembled with the file's own line numbers (blank lines before it).
        std::string text(header + 1, '\n');
        for (size_t i = header + 1; i < lines.size() && lines[i].rfind('[', 0) != 0; ++i)
            text += (lines[i].rfind('%', 0) == 0 ? std::string() : lines[i]) + "\n";
        Diagnostics diags;
        std::optional<Program> program = parseAssembly(text, entry.path().string(), {}, diags);
        INFO(diags.formatAll());
        // An assembler code (P11xx) means the block must not assemble; otherwise it must.
        const bool assemblerCode = code.rfind("P11", 0) == 0;
        if (assemblerCode)
            CHECK_FALSE(program.has_value());
        else
            REQUIRE(program.has_value());
        ShaderStats stats;
        const bool ok = program && validate(*program, diags, &stats);
        INFO(diags.formatAll());
        if (code.empty()) {
            CHECK(ok);
            continue;
        }
        ++fails;
        CHECK_FALSE(ok);
        bool found = false;
        for (const Diagnostic& d : diags.all()) {
            if (d.severity != Severity::Error) continue;
            if (d.code == code && d.loc.line == wantLine && d.loc.col == wantCol) found = true;
            if (d.code != code) CHECK(std::find(also.begin(), also.end(), d.code) != also.end());
        }
        CHECK(found);
    }
    CHECK(files >= 100);
    CHECK(fails >= 80);
}

TEST_CASE("opcode table: components read and destination writes", "[validator][opcodes]") {
    auto row = [](const char* mnemonic, int minor) { return *findOpcode(mnemonic, minor); };
    // Per-component instructions read the write mask's channels; dp3/dp4/bem a fixed set.
    CHECK(componentsRead(row("mad", 1), 2, kMaskG | kMaskA) == (kMaskG | kMaskA));
    CHECK(componentsRead(row("cmp", 4), 0, kMaskB) == kMaskB);
    CHECK(componentsRead(row("dp3", 4), 1, kMaskA) == kMaskRGB);
    CHECK(componentsRead(row("dp4", 2), 0, kMaskR) == kMaskAll);
    CHECK(componentsRead(row("bem", 4), 1, kMaskR | kMaskG) == (kMaskR | kMaskG));
    CHECK(componentsRead(row("add", 1), 2, kMaskAll) == 0);  // no third source
    // Texture-address sources (spec §2.3 formulas).
    CHECK(componentsRead(row("texbem", 1), 0, kMaskAll) == (kMaskR | kMaskG));
    CHECK(componentsRead(row("texbeml", 1), 0, kMaskAll) == kMaskRGB);
    CHECK(componentsRead(row("texreg2ar", 1), 0, kMaskAll) == (kMaskA | kMaskR));
    CHECK(componentsRead(row("texreg2gb", 1), 0, kMaskAll) == (kMaskG | kMaskB));
    CHECK(componentsRead(row("texm3x3spec", 1), 1, kMaskAll) == kMaskRGB);
    CHECK(componentsRead(row("texld", 4), 0, kMaskAll) == kMaskRGB);
    CHECK(componentsReadAny(row("lrp", 1), kMaskRGB) == kMaskRGB);
    // texkill and texdepth read the register their destination token names.
    CHECK(row("texkill", 4).dstReads == kMaskRGB);
    CHECK(row("texdepth", 4).dstReads == (kMaskR | kMaskG));
    // Destinations written: texdepth writes depth only (r5 is read, then unusable).
    for (const char* m : {"texkill", "texm3x2pad", "texm3x3pad", "texm3x2depth", "texdepth", "nop", "phase", "def"})
        CHECK_FALSE(row(m, 4).writesDst);
    for (const char* m : {"mov", "bem", "texcoord", "texcrd", "tex", "texld", "texm3x3", "texdp3", "texm3x3vspec"})
        CHECK(row(m, 4).writesDst);
    for (const OpcodeInfo& r : opcodeTable()) {
        INFO(r.mnemonic);
        if (r.writesDst) CHECK(r.hasDst);
        for (int s = 0; s < 3; ++s) {
            if (s >= r.numSrc) CHECK(r.srcReads[size_t(s)] == 0);
            else CHECK(r.srcReads[size_t(s)] != 0);
            // Only arithmetic instructions read per write mask.
            if (r.srcReads[size_t(s)] == kReadsWriteMask) CHECK(r.cls == OpClass::Arith);
        }
    }
}

TEST_CASE("validator: random programs never crash", "[validator]") {
    // Any well-typed IR (the decoder can produce any row, register number and modifier) must be
    // validated without crashing; run under the sanitizer build for the real check.
    uint32_t state = 12345;
    auto next = [&state](uint32_t n) {
        state = state * 1664525u + 1013904223u;
        return (state >> 8) % n;
    };
    const auto table = opcodeTable();
    for (int round = 0; round < 3000; ++round) {
        Program p;
        p.version = {1, int(1 + next(4))};
        const size_t count = next(16);
        for (size_t i = 0; i < count; ++i) {
            Instruction in;
            in.info = &table[next(uint32_t(table.size()))];
            in.coissue = next(4) == 0;
            in.dst.type = RegType(next(4));
            in.dst.index = uint8_t(next(4) == 0 ? next(256) : next(7));
            in.dst.mask = uint8_t(next(16));
            in.dst.saturate = next(2);
            in.dst.shift = int8_t(int(next(9)) - 4);
            for (Src& s : in.src) {
                s.type = RegType(next(4));
                s.index = uint8_t(next(4) == 0 ? next(256) : next(7));
                s.swizzle = uint8_t(next(4) == 0 ? next(256) : 0xE4);
                s.mod = SrcMod(next(11));
            }
            p.instructions.push_back(in);
        }
        Diagnostics d;
        ShaderStats stats;
        validate(p, d, &stats);
        CHECK(stats.table.size() == count);
        CHECK_FALSE(statsToJson(stats).empty());
    }
}
