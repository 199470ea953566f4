// runner/random_program: random ps_1_x cases for differential fuzzing. A seed gives one case;
// 2000 cases (500 per version) assemble and validate without a diagnostic and cover every
// instruction of each version with the modifiers, selectors, shifts and pairs the versions have,
// and their environments every feature the renderers must agree on (texture formats, volumes,
// mip chains, filters, address modes, perspective, depth, blending, alpha test, fog, write masks,
// float targets, hardware classes and profiles), each in some cases only; 300 generated
// .ps11test files (and 100 on a 13x5 target) parse, round-trip their shader through the
// disassembler and draw on the emu device; the shrinker reduces the program and the environment
// and keeps what its predicate needs.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "emu/device.h"
#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/disassembler.h"
#include "ps11/encoder.h"
#include "ps11/hardware.h"
#include "ps11/testfile.h"
#include "ps11/validator.h"
#include "runner/random_program.h"
#include "runner/test_draw.h"

using namespace ps11test;

namespace {

ps11test::RandomCase caseOf(uint64_t seed, int minor, int width = 8, int height = 8) {
    std::mt19937_64 rng(seed);
    RandomCaseOptions options;
    options.minor = minor;
    options.width = width, options.height = height;
    return randomCase(rng, options);
}

ps11::TestFile parsed(const std::string& text) {
    ps11::TestFile file;
    std::vector<ps11::TestFileError> errors;
    const bool ok = ps11::parseTestFile(text, "random.ps11test", file, errors);
    for (const ps11::TestFileError& e : errors) UNSCOPED_INFO(ps11::formatTestFileError("random.ps11test", e));
    REQUIRE(ok);
    return file;
}

// True when the device may skip the draw without changing a pixel (docs/output-merger.md
// "writesNothing()"), so that it shades nothing.
bool writesNothing(const ps11::TestFile& file) {
    const ps11::RenderStateDesc& rs = file.renderState;
    const bool depth = file.renderTarget.depth.value;
    if (rs.alphaTest.value && rs.alphaFunc.value == ps11::CompareFunc::Never) return true;
    if (depth && rs.zFunc.value == ps11::CompareFunc::Never) return true;
    if (depth && rs.zWrite.value) return false;
    if (rs.colorWrite.value == 0) return true;
    // Blended as 0·src + 1·dst on every channel.
    using B = ps11::Blend;
    const ps11::BlendOp op = rs.blendOp.value;
    return rs.alphaBlend.value && rs.srcBlend.value == B::Zero && rs.destBlend.value == B::One &&
           (op == ps11::BlendOp::Add || op == ps11::BlendOp::RevSubtract);
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

TEST_CASE("random programs: the environments cover every feature, each in some cases only", "[random]") {
    // Counted over the 2000 cases: cases with the feature (or, for texture features, sampled
    // stages with it). Each feature is drawn with its own probability (30-45 %), so it must
    // appear, and the main ones must stay out of most cases too.
    std::map<std::string, int> cases, stages;
    std::set<ps11::TexFormat> formats;
    std::set<ps11::Blend> blends;
    std::set<ps11::BlendOp> blendOps;
    std::set<ps11::CompareFunc> alphaFuncs, zFuncs;
    std::set<std::string> classes;
    std::set<ps11::Precision> precisions;
    std::set<ps11::TexFormat> targetFormats;
    std::set<ps11::TextureAddress> addressModes;
    int totalStages = 0;
    for (const RandomCase& c : corpus()) {
        const ps11::TestFile file = parsed(c.testText);
        const ps11::RequireDesc& req = file.require;
        if (req.hardware.isSet()) {
            ++cases["hardware"];
            classes.insert(std::string(req.hardware.value->name));
            CHECK(req.hardware.value->maxMinor >= c.minor);
        }
        if (req.precision.isSet()) ++cases["precision"], precisions.insert(req.precision.value);
        const ps11::RenderTargetDesc& rt = file.renderTarget;
        targetFormats.insert(rt.format.value);
        if (ps11::isFloatFormat(rt.format.value)) ++cases["float target"];
        if (rt.depth.value) {
            ++cases["depth"];
            if (rt.depthClear != 1.0f) ++cases["depth clear"];
        }
        const ps11::RenderStateDesc& rs = file.renderState;
        if (rs.alphaBlend.value) {
            ++cases["blend"];
            blends.insert(rs.srcBlend.value), blends.insert(rs.destBlend.value), blendOps.insert(rs.blendOp.value);
            if (rs.blendFactor.isSet()) ++cases["blend factor"];
        }
        if (rs.alphaTest.value) ++cases["alpha test"], alphaFuncs.insert(rs.alphaFunc.value);
        if (rs.fog.value) ++cases["fog"];
        if (rs.zFunc.isSet()) zFuncs.insert(rs.zFunc.value);
        if (rs.zWrite.isSet() && !rs.zWrite.value) ++cases["zwrite off"];
        if (rs.colorWrite.value != 15) ++cases["colour write mask"];
        if (rs.colorWrite.value == 0) ++cases["colour write none"];
        CHECK((rs.zFunc.isSet() || rs.zWrite.isSet()) <= rt.depth.value);

        const auto& draw = std::get<ps11::DrawPrimitives>(file.commands.at(0).op);
        std::set<float> rhw, z;
        bool wide = false;
        for (const ps11::Vertex& v : draw.vertices) {
            rhw.insert(v.position[3]);
            z.insert(v.position[2]);
            for (int t = 0; t < 8; ++t)
                if (v.texComponents[size_t(t)]) wide = wide || std::fabs(v.tex[size_t(t)][0]) > 1.5f;
        }
        if (rhw.size() > 1) ++cases["perspective"];
        if (z.size() > 1) ++cases["varying z"];
        CHECK((z.size() > 1) <= rt.depth.value);
        if (draw.vertices.size() > 6) ++cases["extra triangles"];
        if (wide) ++cases["wide coordinates"];

        for (const ps11::TextureDesc& t : file.textures) {
            ++totalStages;
            formats.insert(t.format.value);
            if (t.isVolume()) ++stages["volume"];
            if (t.levels.value == 0) ++stages["generated chain"];
            if (t.levels.value > 1) ++stages["given chain"];
            if (t.levels.value > 1 && t.isVolume()) ++stages["volume chain"];
            if ((t.width & (t.width - 1)) || (t.height & (t.height - 1))) ++stages["not a power of two"];
            const ps11::SamplerDesc* s = file.sampler(t.stage);
            REQUIRE(s);
            if (s->minFilter.value != s->magFilter.value) ++stages["min != mag"];
            if (s->mipFilter.value == ps11::Filter::Point) ++stages["mip point"];
            if (s->mipFilter.value == ps11::Filter::Linear) ++stages["mip linear"];
            if (s->mipFilter.value != ps11::Filter::None && t.levels.value != 1) ++stages["mip filter on a chain"];
            addressModes.insert(s->addressU.value), addressModes.insert(s->addressV.value);
            if (t.isVolume()) {
                addressModes.insert(s->addressW.value);
                if (s->addressW.value == ps11::TextureAddress::MirrorOnce) ++stages["mirroronce w"];
            }
        }
    }
    for (const auto& [name, n] : cases) UNSCOPED_INFO(name << ": " << n << " of 2000 cases");
    for (const auto& [name, n] : stages) UNSCOPED_INFO(name << ": " << n << " of " << totalStages << " stages");
    // Every feature appears …
    for (const char* name : {"hardware", "precision", "float target", "depth", "depth clear", "blend", "blend factor",
                             "alpha test", "fog", "zwrite off", "colour write mask", "colour write none", "perspective",
                             "varying z", "extra triangles", "wide coordinates"})
        CHECK(cases[name] > 20);
    for (const char* name : {"volume", "generated chain", "given chain", "volume chain", "not a power of two",
                             "min != mag", "mip point", "mip linear", "mip filter on a chain", "mirroronce w"})
        CHECK(stages[name] > 20);
    // … and the ones drawn per case stay out of most cases (probabilities 25-45 %).
    for (const char* name : {"hardware", "precision", "float target", "depth", "blend", "alpha test", "fog",
                             "colour write mask", "perspective", "extra triangles", "wide coordinates"}) {
        INFO(name);
        CHECK(cases[name] > 300);
        CHECK(cases[name] < 1100);
    }
    CHECK(stages["volume"] < totalStages / 2);
    // Every texture format, render target format, class, profile, address mode, blend factor,
    // blend operation and compare function.
    CHECK(formats.size() == 13);
    CHECK(targetFormats == std::set<ps11::TexFormat>{ps11::TexFormat::A8R8G8B8, ps11::TexFormat::X8R8G8B8,
                                                     ps11::TexFormat::A16B16G16R16F, ps11::TexFormat::A32B32G32R32F});
    CHECK(classes.size() == ps11::hardwareClasses().size());
    CHECK(precisions.size() == 4);
    CHECK(addressModes.size() == 5);
    CHECK(blends.size() == 15);
    CHECK(blendOps.size() == 5);
    CHECK(alphaFuncs.size() == 8);
    CHECK(zFuncs.size() == 8);
}

TEST_CASE("random programs: 300 generated files parse and draw on the emu device", "[random]") {
    // Seeds 10000 … 10299 on the default 8x8 target, then 100 on a 13x5 one (odd sides: partial
    // quads at the edges).
    int shaded = 0, skipped = 0;
    for (uint64_t seed = 10000; seed < 10400; ++seed) {
        const bool wide = seed >= 10300;
        const RandomCase c = caseOf(seed, 0, wide ? 13 : 8, wide ? 5 : 8);
        INFO("seed " << seed << "\n" << c.testText);
        const ps11::TestFile file = parsed(c.testText);
        REQUIRE(file.pixelShader.present());
        CHECK(file.require.versionMinor.value == c.minor);
        CHECK(file.renderTarget.size.value == std::array<uint32_t, 2>{wide ? 13u : 8u, wide ? 5u : 8u});

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
        CHECK(draw->type == ps11::PrimitiveType::TriangleList);
        CHECK(draw->vertices.size() >= 6);
        CHECK(draw->vertices.size() <= 15);
        CHECK(draw->vertices.size() % 3 == 0);

        // The class, profile and MaxValue `ps11 test` and `ps11 compare` use for the file.
        const ps11::RequireDesc& req = file.require;
        std::optional<ps11::Precision> precision;
        if (req.precision.isSet()) precision = req.precision.value;
        const ps11::HardwareConfig hw = ps11::resolveHardware(req.hardware.value, c.minor, precision, 0);
        std::string error;
        std::unique_ptr<ps11test::DrawRunner> runner =
            ps11test::DrawRunner::create(file, "random.ps11test", &*program, hw, error);
        INFO(error);
        REQUIRE(runner);
        CHECK(runner->draw(file.commands[0], error));
        if (writesNothing(file)) {
            ++skipped;
        } else {
            // Shaded lanes, or tiles the interval evaluator decided without shading (a program
            // whose r0 is one constant everywhere).
            const ps11test::DrawTally& t = runner->tally();
            CHECK(t.pixelsShaded + t.tilesFilled + t.tilesCopied + t.tilesSkipped > 0);
            ++shaded;
        }
        std::vector<ps11::Vec4> pixels;
        CHECK(runner->targetPixels(pixels, error));
        CHECK(pixels.size() == size_t(wide ? 65 : 64));
    }
    // The draws that can change nothing are few.
    CHECK(shaded > 360);
    CHECK(skipped < 40);
}

TEST_CASE("random programs: rows and quads draw the same bytes in every profile", "[random][draw]") {
    // Every generated program (dependent reads, texkill, texdepth, projected reads, any version),
    // textures with or without mip chains, depth and fog states: drawn by a device with its row
    // paths (the fx and float row paths, and spans of one row for what they leave whose lookups
    // are ps11::lodFree) and by one drawing the general way: every triangle in 2×2 quads, every
    // lookup by the reference sampler (DrawRunner::create's fastPaths). The targets must be
    // identical bit for bit; where every sampled texture is lodFree no helper lane is shaded.
    int rows = 0, quads = 0, rowPathDepthFog = 0, x8Targets = 0;
    for (uint64_t seed = 20000; seed < 20160; ++seed) {
        const RandomCase c = caseOf(seed, 0, 13, 7);
        INFO("seed " << seed << "\n" << c.testText);
        const ps11::TestFile file = parsed(c.testText);
        ps11::Diagnostics diags;
        std::optional<ps11::Program> program = assemble(file.pixelShader.textWithFileLines(), diags);
        REQUIRE(program);
        bool lodFree = true;  // (a texture the program does not sample may make this false: never wrong)
        for (const ps11::TextureDesc& t : file.textures) {
            const ps11::SamplerDesc none{};
            const ps11::SamplerDesc* sd = file.sampler(t.stage);
            const ps11::SamplerDesc& st = sd ? *sd : none;
            lodFree = lodFree && (t.levels.value == 1 || st.mipFilter.value == ps11::Filter::None) &&
                      (st.minFilter.value == ps11::Filter::Linear) == (st.magFilter.value == ps11::Filter::Linear);
        }
        // The four profiles overridden (float without 8-bit weights), then the D3D9 class in its
        // own float profile, whose filter weights are 8-bit (the float row path's weights8).
        for (int config = 0; config < 5; ++config) {
            const ps11::Precision p =
                std::array<ps11::Precision, 5>{ps11::Precision::Fx8, ps11::Precision::Fx12, ps11::Precision::Float,
                                               ps11::Precision::Ideal, ps11::Precision::Float}[size_t(config)];
            INFO("precision " << ps11::precisionName(p) << (config == 4 ? " (d3d9 class, 8-bit weights)" : ""));
            const ps11::HardwareConfig hw =
                config == 4 ? ps11::resolveHardware(ps11::findHardware("d3d9"), program->version.minor, std::nullopt, 0)
                            : ps11::resolveHardware(file.require.hardware.value, program->version.minor, p, 0);
            if (config == 4) REQUIRE(hw.weightBits == 8);
            std::string error;
            auto rowRunner = ps11test::DrawRunner::create(file, "random.ps11test", &*program, hw, error);
            auto quadRunner = ps11test::DrawRunner::create(file, "random.ps11test", &*program, hw, error, false);
            INFO(error);
            REQUIRE(rowRunner);
            REQUIRE(quadRunner);
            const bool drawn = rowRunner->draw(file.commands[0], error);
            CHECK(quadRunner->draw(file.commands[0], error) == drawn);
            std::vector<ps11::Vec4> a, b;
            REQUIRE(rowRunner->targetPixels(a, error));
            REQUIRE(quadRunner->targetPixels(b, error));
            REQUIRE(a.size() == b.size());
            CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof a[0]) == 0);
            // Every store into an X8R8G8B8 target leaves its X byte 0xff (on both paths): the
            // device samples such a target where it lies after a whole clear (Resource::padOnes).
            if (file.renderTarget.format.value == ps11::TexFormat::X8R8G8B8) {
                ++x8Targets;
                for (ps11test::DrawRunner* r : {rowRunner.get(), quadRunner.get()}) {
                    emu::Handle rt{};
                    REQUIRE(r->device().GetRenderTarget(0, &rt) == emu::D3D_OK);
                    size_t notSet = 0;
                    REQUIRE(r->device().readSurface(rt, [&](const emu::D3DLOCKED_RECT& lr) {
                        for (uint32_t y = 0; y < file.renderTarget.size.value[1]; ++y)
                            for (uint32_t x = 0; x < file.renderTarget.size.value[0]; ++x)
                                notSet += static_cast<const uint8_t*>(lr.pBits)[size_t(y) * size_t(lr.Pitch) +
                                                                                 4 * size_t(x) + 3] != 0xff;
                    }) == emu::D3D_OK);
                    CHECK(notSet == 0);
                }
            }
            const emu::DrawStats& rs = rowRunner->device().lastDrawStats();
            const emu::DrawStats& qs = quadRunner->device().lastDrawStats();
            CHECK(rs.pixelsCovered == qs.pixelsCovered);
            CHECK(rs.pixelsWritten == qs.pixelsWritten);
            CHECK(qs.pixelsRowPath == 0);
            // Depth and fog draws the fx8, fx12 and float row paths drew wholly (not spans).
            if (drawn && (file.renderTarget.depth.value || file.renderState.fog.value) && rs.pixelsCovered > 0 &&
                rs.pixelsRowPath == rs.pixelsCovered)
                ++rowPathDepthFog;
            if (!drawn || qs.pixelsShaded == qs.pixelsCovered) continue;  // (no helper lanes to tell them apart)
            if (lodFree) {
                CHECK(rs.pixelsShaded <= rs.pixelsCovered);  // (fewer where tiles were filled or skipped)
                ++rows;
            } else if (rs.pixelsShaded > rs.pixelsCovered) {
                ++quads;
            }
        }
    }
    // Both kinds occur: lookups free of the level of detail in rows, mip chains in quads; and
    // the row paths take depth-tested and fogged draws of plain reads.
    INFO(rows << " draws in rows, " << quads << " in quads, " << rowPathDepthFog << " with depth or fog by a row path");
    CHECK(rows > 200);
    CHECK(quads > 50);
    CHECK(rowPathDepthFog > 20);
    CHECK(x8Targets > 20);
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

TEST_CASE("random programs: the shrinker leaves out the environment a failure does not need", "[random]") {
    // A "failure" that needs a mul, fog and some texture: every other state, section, extra
    // triangle, mip level and the perspective go; one texture, at level 0, stays.
    const auto needs = [](const RandomCase& c) {
        return containsMul(c) && c.testText.find("\nfog on") != std::string::npos &&
               c.testText.find("\n[texture ") != std::string::npos;
    };
    int shrunk = 0;
    for (uint64_t seed = 0; shrunk < 4 && seed < 2000; ++seed) {
        const RandomCase start = caseOf(seed, int(1 + seed % 4));
        const std::string& text = start.testText;
        if (!needs(start) || text.find("depth on") == std::string::npos || text.find("\nlevels ") == std::string::npos)
            continue;
        ++shrunk;
        INFO("seed " << seed << "\n" << text);
        const RandomCase small = shrinkCase(start, needs);
        INFO("shrunk to\n" << small.testText);
        CHECK(needs(small));
        CHECK(small.lines.size() <= 2);
        CHECK(small.testText == caseTestText(small));
        const ps11::TestFile file = parsed(small.testText);
        CHECK_FALSE(file.require.hardware.isSet());
        CHECK_FALSE(file.require.precision.isSet());
        CHECK_FALSE(file.renderTarget.format.isSet());
        CHECK_FALSE(file.renderTarget.clear.isSet());
        CHECK_FALSE(file.renderTarget.depth.value);
        const ps11::RenderStateDesc& rs = file.renderState;
        CHECK(rs.fog.value);
        CHECK_FALSE(rs.alphaBlend.value);
        CHECK_FALSE(rs.alphaTest.value);
        CHECK(rs.colorWrite.value == 15);
        CHECK(file.textures.size() == 1);
        CHECK(file.textures.at(0).levels.value == 1);
        CHECK(file.samplers.empty());
        CHECK(file.stages.empty());
        CHECK(file.constants.empty());
        const auto& draw = std::get<ps11::DrawPrimitives>(file.commands.at(0).op);
        CHECK(draw.vertices.size() == 6);
        for (const ps11::Vertex& v : draw.vertices) {
            CHECK(v.position[2] == 0);
            CHECK(v.position[3] == 1);
        }
    }
    CHECK(shrunk == 4);
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
