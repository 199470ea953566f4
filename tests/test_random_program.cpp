// tools/random_program: random ps_1_x cases for differential fuzzing. A seed gives one case;
// 2000 cases (500 per version) assemble and validate without a diagnostic and cover every
// instruction of each version with the modifiers, selectors, shifts and pairs the versions have;
// 300 generated .ps11test files parse, round-trip their shader through the disassembler and draw
// on the emu device; the shrinker reduces and keeps what its predicate needs.
#include <catch2/catch.hpp>

#include <map>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/disassembler.h"
#include "ps11/encoder.h"
#include "ps11/hardware.h"
#include "ps11/testfile.h"
#include "ps11/validator.h"
#include "tools/random_program.h"
#include "tools/test_draw.h"

using namespace ps11tools;

namespace {

ps11tools::RandomCase caseOf(uint64_t seed, int minor) {
    std::mt19937_64 rng(seed);
    RandomCaseOptions options;
    options.minor = minor;
    return randomCase(rng, options);
}

// The 2000 cases of the validity and coverage tests: seed s is version 1 + s % 4.
const std::vector<RandomCase>& corpus() {
    static const std::vector<RandomCase> cases = [] {
        std::vector<RandomCase> out;
        for (uint64_t seed = 0; seed < 2000; ++seed) out.push_back(caseOf(seed, int(1 + seed % 4)));
        return out;
    }();
    return cases;
}

std::optional<ps11::Program> assemble(const std::string& text, ps11::Diagnostics& diags) {
    std::optional<ps11::Program> program = ps11::parseAssembly(text, "case.psh", {}, diags);
    if (program) ps11::validate(*program, diags);
    return program;
}

// The mnemonic of a body line: "+mul_x2_sat r0.a, ..." → "mul".
std::string mnemonicOf(const std::string& line) {
    const size_t begin = line.starts_with("+") ? 1 : 0;
    return line.substr(begin, line.find_first_of("_ ", begin) - begin);
}

bool containsMul(const RandomCase& c) {
    for (const std::string& line : c.lines)
        if (mnemonicOf(line) == "mul") return true;
    return false;
}

}  // namespace

TEST_CASE("random programs: a seed gives one case", "[random]") {
    for (uint64_t seed : {0u, 1u, 77u, 123456789u}) {
        for (int minor : {0, 1, 4}) {
            const RandomCase a = caseOf(seed, minor), b = caseOf(seed, minor);
            CHECK(a.minor == b.minor);
            CHECK(a.lines == b.lines);
            CHECK(a.testText == b.testText);
            if (minor) CHECK(a.minor == minor);
        }
    }
    // One engine gives a new case each call.
    std::mt19937_64 rng(5);
    const RandomCase first = randomCase(rng, {}), second = randomCase(rng, {});
    CHECK(first.testText != second.testText);
}

TEST_CASE("random programs: 2000 seeds assemble and validate without a diagnostic", "[random]") {
    for (const RandomCase& c : corpus()) {
        INFO(c.shaderText());
        ps11::Diagnostics diags;
        std::optional<ps11::Program> program = assemble(c.shaderText(), diags);
        INFO(diags.formatAll());
        REQUIRE(program);
        CHECK(diags.all().empty());
        CHECK(isCleanProgram(c.minor, c.lines));
        CHECK(c.shaderText().starts_with("ps_1_" + std::to_string(c.minor) + "\n"));
        CHECK(c.testText.find(c.shaderText()) != std::string::npos);
        CHECK(caseTestText(c) == c.testText);
    }
}

TEST_CASE("random programs: every instruction and modifier of each version appears", "[random]") {
    // Measured over the 2000 cases (500 per version), in cases that hold the row: every
    // arithmetic and texture row legal in the version appears; the rarest are the rows that end
    // a texm3x3 sequence (5 to 15 cases each; texm3x3tex of ps_1_2 is the rarest), bem (21) and
    // texdepth (40) in ps_1_4; co-issued pairs are in 172 (ps_1_1) to 216 (ps_1_2) cases.
    std::map<int, std::map<std::string, int>> mnemonics;
    std::map<int, std::set<ps11::SrcMod>> sourceMods;
    std::map<int, std::set<int>> shifts;
    std::map<int, std::set<uint8_t>> selectors;  // arithmetic sources
    std::map<int, int> pairs, saturated, defs, phases, casesOf;
    for (const RandomCase& c : corpus()) {
        ps11::Diagnostics diags;
        std::optional<ps11::Program> program = assemble(c.shaderText(), diags);
        REQUIRE(program);
        ++casesOf[c.minor];
        bool pair = false;
        for (const ps11::Instruction& in : program->instructions) {
            ++mnemonics[c.minor][std::string(in.info->mnemonic)];
            pair = pair || in.coissue;
            if (in.opcode() == ps11::Opcode::Def) ++defs[c.minor];
            if (in.opcode() == ps11::Opcode::Phase) ++phases[c.minor];
            if (in.info->cls != ps11::OpClass::Arith) {
                for (size_t s = 0; s < in.info->numSrc; ++s) sourceMods[c.minor].insert(in.src[s].mod);
                continue;
            }
            shifts[c.minor].insert(in.dst.shift);
            if (in.dst.saturate) ++saturated[c.minor];
            for (size_t s = 0; s < in.info->numSrc; ++s) {
                sourceMods[c.minor].insert(in.src[s].mod);
                selectors[c.minor].insert(in.src[s].swizzle);
            }
        }
        if (pair) ++pairs[c.minor];
    }
    for (int minor = 1; minor <= 4; ++minor) {
        INFO("ps_1_" << minor);
        CHECK(casesOf[minor] == 500);
        for (const ps11::OpcodeInfo& row : ps11::opcodeTable()) {
            if (!(row.versions & ps11::versionBit(minor)) || row.cls == ps11::OpClass::Setup || !row.hasDst) continue;
            INFO(row.mnemonic);
            CHECK(mnemonics[minor][std::string(row.mnemonic)] > 0);
        }
        CHECK(pairs[minor] > 50);
        CHECK(saturated[minor] > 50);
        CHECK(defs[minor] > 50);
        CHECK((phases[minor] > 50) == (minor == 4));
        using M = ps11::SrcMod;
        for (M mod : {M::None, M::Neg, M::Bias, M::BiasNeg, M::Sign, M::SignNeg, M::Comp})
            CHECK(sourceMods[minor].count(mod));
        CHECK(sourceMods[minor].count(M::X2) == (minor == 4));
        CHECK(sourceMods[minor].count(M::Dz) == (minor == 4));
        CHECK(sourceMods[minor].count(M::Dw) == (minor == 4));
        const std::set<int> expectShifts =
            minor == 4 ? std::set<int>{-3, -2, -1, 0, 1, 2, 3} : std::set<int>{-1, 0, 1, 2};
        CHECK(shifts[minor] == expectShifts);
        const std::set<uint8_t> expectSelectors =
            minor == 4 ? std::set<uint8_t>{0xE4, 0x00, 0x55, 0xAA, 0xFF} : std::set<uint8_t>{0xE4, 0xAA, 0xFF};
        CHECK(selectors[minor] == expectSelectors);
    }
}

TEST_CASE("random programs: 300 generated files parse and draw on the emu device", "[random]") {
    for (uint64_t seed = 10000; seed < 10300; ++seed) {
        const RandomCase c = caseOf(seed, 0);
        INFO("seed " << seed << "\n" << c.testText);
        ps11::TestFile file;
        std::vector<ps11::TestFileError> errors;
        const bool parsed = ps11::parseTestFile(c.testText, "random.ps11test", file, errors);
        for (const ps11::TestFileError& e : errors) UNSCOPED_INFO(ps11::formatTestFileError("random.ps11test", e));
        REQUIRE(parsed);
        REQUIRE(file.pixelShader.present());
        CHECK(file.require.versionMinor.value == c.minor);

        ps11::Diagnostics diags;
        std::optional<ps11::Program> program = assemble(file.pixelShader.textWithFileLines(), diags);
        INFO(diags.formatAll());
        REQUIRE(program);
        REQUIRE(diags.all().empty());
        // Tokens → disassembly → tokens, as `ps11 test` checks every valid shader.
        const std::vector<uint32_t> tokens = ps11::encode(*program);
        ps11::Diagnostics rt;
        std::optional<ps11::Program> decoded = ps11::decode(tokens, rt.addFile("tokens"), rt);
        REQUIRE(decoded);
        std::optional<ps11::Program> again = ps11::parseAssembly(ps11::disassemble(*decoded), "again", {}, rt);
        REQUIRE(again);
        CHECK(ps11::encode(*again) == tokens);

        const uint32_t sampled = ps11::sampledStages(*program);
        for (int stage = 0; stage < 8; ++stage) CHECK(bool(file.texture(stage)) == bool(sampled & (1u << stage)));
        REQUIRE(file.commands.size() == 1);
        const auto* draw = std::get_if<ps11::DrawPrimitives>(&file.commands[0].op);
        REQUIRE(draw);
        CHECK(draw->pretransformed);
        CHECK(draw->vertices.size() == 6);

        const ps11::HardwareConfig hw = ps11::resolveHardware(nullptr, c.minor, std::nullopt, 0);
        std::string error;
        std::unique_ptr<ps11::DrawRunner> runner =
            ps11::DrawRunner::create(file, "random.ps11test", &*program, hw, error);
        INFO(error);
        REQUIRE(runner);
        CHECK(runner->draw(file.commands[0], error));
        CHECK(runner->tally().pixelsShaded > 0);
    }
}

TEST_CASE("random programs: the shrinker keeps a mul and little else", "[random]") {
    int shrunk = 0;
    for (uint64_t seed = 0; shrunk < 12; ++seed) {
        const RandomCase start = caseOf(seed, int(1 + seed % 4));
        if (!containsMul(start) || start.lines.size() <= 3) continue;
        ++shrunk;
        INFO("seed " << seed << "\n" << start.shaderText());
        const RandomCase small = shrinkCase(start, containsMul);
        INFO("shrunk to\n" << small.shaderText());
        CHECK(small.minor == start.minor);
        CHECK(small.lines.size() <= 2);
        CHECK(containsMul(small));
        CHECK(isCleanProgram(small.minor, small.lines));
        CHECK(small.testText == caseTestText(small));
        ps11::TestFile file;
        std::vector<ps11::TestFileError> errors;
        CHECK(ps11::parseTestFile(small.testText, "small.ps11test", file, errors));
    }
}

TEST_CASE("random programs: the shrinker returns a case that never fails unchanged", "[random]") {
    for (uint64_t seed : {3u, 4u, 5u, 6u}) {
        const RandomCase start = caseOf(seed, int(1 + seed % 4));
        int calls = 0;
        const RandomCase same = shrinkCase(start, [&](const RandomCase&) {
            ++calls;
            return false;
        });
        CHECK(calls > 0);
        CHECK(same.minor == start.minor);
        CHECK(same.lines == start.lines);
        CHECK(same.testText == start.testText);
    }
}

TEST_CASE("random programs: caseTestText replaces only the shader", "[random]") {
    RandomCase c = caseOf(42, 2);
    const std::string before = c.testText;
    c.lines = {"mov r0, v0"};
    const std::string after = caseTestText(c);
    const size_t shader = before.find("[pixel shader]\n") + 15;
    CHECK(after.substr(0, shader) == before.substr(0, shader));
    CHECK(after.substr(shader, 19) == "ps_1_2\nmov r0, v0\n\n");
    CHECK(after.substr(after.find("[test]")) == before.substr(before.find("[test]")));
}
