// The range proof (ps11/range_proof.h, `ps11 check --ranges`):
// - Sousa's squaring `mov_x4` then `mul` clamps from t0 > 0.25 on the 1.1-class card, and the
//   proof says so; a shader that cannot clamp is range-safe;
// - the bound on |fx − float| holds: the corpus and random programs run on the executor in fx8,
//   fx12 and float (the same MaxValue) over random inputs and bilinear 8-bit textures, and no
//   difference of r0 exceeds the proof's bound for its channel.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <catch2/catch.hpp>

#include "ps11/assembler.h"
#include "ps11/executor.h"
#include "ps11/hardware.h"
#include "ps11/range_proof.h"
#include "ps11/testfile.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"
#include "ps11/validator.h"
#include "runner/random_program.h"

using namespace ps11;

namespace {

std::optional<Program> assembleOk(const std::string& text) {
    Diagnostics diags;
    std::optional<Program> p = parseAssembly(text, "t.psh", AssembleOptions{}, diags);
    if (p) validate(*p, diags);
    if (!p || diags.hasErrors()) return std::nullopt;
    return p;
}

RangeProofSetup setupFor(const Program& p) {
    RangeProofSetup s;
    s.options = executorOptionsFor(resolveHardware(nullptr, p.version.minor, std::nullopt, 0));
    return s;
}

// A random 4×4 A8R8G8B8 texture.
std::shared_ptr<const Texture> randomTexture(std::mt19937_64& rng) {
    std::vector<uint8_t> bytes(4 * 4 * 4);
    for (uint8_t& b : bytes) b = uint8_t(rng() & 0xff);
    TextureLevelBytes level;
    level.width = level.height = 4;
    level.data = bytes.data();
    level.rowPitch = 16;
    std::string error;
    std::optional<Texture> t = Texture::fromLevels(TexFormat::A8R8G8B8, false, &level, 1, SignedDecode::Snorm, error);
    REQUIRE(t);
    return std::make_shared<const Texture>(std::move(*t));
}

struct Measured {
    double worst[4] = {0, 0, 0, 0};  // |fx − float| in 8-bit levels, per channel
    int pixels = 0;
};

// Runs `program` in `fx` and in float at MaxValue m over `count` random pixels.
Measured measure(const Program& program, const RangeProofSetup& setup, Precision fx, float m, std::mt19937_64& rng,
                 int count) {
    Diagnostics diags;
    ExecutorOptions ofx = setup.options, ofl = setup.options;
    ofx.precision = fx, ofx.maxValue = m, ofx.path = ExecPath::Generic;
    ofl.precision = Precision::Float, ofl.maxValue = m;
    std::unique_ptr<Executor> ex = Executor::create(program, ofx, diags), ef = Executor::create(program, ofl, diags);
    REQUIRE(ex);
    REQUIRE(ef);
    for (int c = 0; c < 8; ++c) ex->setConstant(c, setup.constants[size_t(c)]), ef->setConstant(c, setup.constants[size_t(c)]);
    TextureSampler sx, sf;
    sx.setWeightBits(8);  // the fx profiles' 8-bit weights
    sf.setWeightBits(0);  // an overriding float profile: float32 weights
    SamplerState ss;
    ss.minFilter = ss.magFilter = Filter::Linear;
    for (int t = 0; t < kMaxTextureStages; ++t) {
        std::shared_ptr<const Texture> tex = randomTexture(rng);
        sx.bind(t, tex), sf.bind(t, tex);
        sx.setSamplerState(t, ss), sf.setSamplerState(t, ss);
    }
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> color[2][4], tc[kMaxTexCoordSets][4];
    for (auto& v : color)
        for (auto& c : v) c.resize(size_t(count));
    for (auto& v : tc)
        for (auto& c : v) c.resize(size_t(count));
    for (int i = 0; i < count; ++i) {
        for (auto& v : color)
            for (auto& c : v) c[size_t(i)] = unit(rng);
        for (auto& v : tc)
            for (auto& c : v) c[size_t(i)] = unit(rng);
    }
    PixelInputs in;
    in.count = count;
    for (int v = 0; v < 2; ++v)
        for (int c = 0; c < 4; ++c) in.color[v][c] = color[v][c].data();
    for (int t = 0; t < kMaxTexCoordSets; ++t)
        for (int c = 0; c < 4; ++c) in.texcoord[t][c] = tc[t][c].data();
    std::vector<float> ox[4], of[4];
    std::vector<uint8_t> kx(static_cast<size_t>(count)), kf(static_cast<size_t>(count));
    PixelOutputs px, pf;
    for (int c = 0; c < 4; ++c) {
        ox[c].resize(size_t(count)), of[c].resize(size_t(count));
        px.color[c] = ox[c].data(), pf.color[c] = of[c].data();
    }
    px.killed = kx.data(), pf.killed = kf.data();
    ex->run(in, sx, px);
    ef->run(in, sf, pf);
    Measured r;
    for (int i = 0; i < count; ++i) {
        if (kx[size_t(i)] || kf[size_t(i)]) continue;  // the bound is for pixels both keep
        ++r.pixels;
        for (int c = 0; c < 4; ++c)
            r.worst[c] = std::max(r.worst[c], std::fabs(double(ox[c][size_t(i)]) - double(of[c][size_t(i)])) * 255.0);
    }
    return r;
}

struct Tally {
    int programs = 0, bounded = 0;
    double worstRatio = 0;  // the largest measured / bound over bounded channels with a bound > 0
    double sumRatio = 0;
    int ratios = 0;
};

// Checks the bound of both fx profiles on one program; returns false if it did not hold.
void checkBound(const Program& program, const std::string& name, std::mt19937_64& rng, Tally& tally) {
    RangeProofSetup setup = setupFor(program);
    std::uniform_real_distribution<float> c(-1.0f, 1.0f);
    for (auto& k : setup.constants)
        for (float& x : k) x = c(rng);
    Diagnostics diags;
    std::optional<RangeProof> proof = proveRanges(program, setup, diags);
    REQUIRE(proof);
    ++tally.programs;
    for (Precision fx : {Precision::Fx8, Precision::Fx12}) {
        const LevelBound& b = fx == Precision::Fx8 ? proof->fx8 : proof->fx12;
        const float m = float(std::min(double(proof->options.maxValue), maxRepresentableValue(fx)));
        const Measured got = measure(program, setup, fx, m, rng, 512);
        for (int ch = 0; ch < 4; ++ch) {
            const double bound = b.levels[size_t(ch)];
            if (!std::isfinite(bound)) continue;
            INFO(name << " " << precisionName(fx) << " channel " << ch << ": measured " << got.worst[ch]
                      << " levels, bound " << bound);
            CHECK(got.worst[ch] <= bound + 1e-9);
            if (bound > 0) {
                const double ratio = got.worst[ch] / bound;
                tally.worstRatio = std::max(tally.worstRatio, ratio);
                tally.sumRatio += ratio;
                ++tally.ratios;
            }
        }
        if (b.bounded) ++tally.bounded;
    }
}

std::string slurp(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

}  // namespace

TEST_CASE("range proof: Sousa's mov_x4 then mul clamps from t0 > 0.25 on the 1.1-class card", "[ranges]") {
    std::optional<Program> p = assembleOk("ps_1_1\ntex t0\nmov_x4 r1, t0\nmul r0, r1, t0\n");
    REQUIRE(p);
    Diagnostics diags;
    std::optional<RangeProof> proof = proveRanges(*p, setupFor(*p), diags);
    REQUIRE(proof);
    REQUIRE(proof->instructions.size() == 3);
    const InstructionRange& movx4 = proof->instructions[1];
    CHECK(movx4.loc.line == 3);
    CHECK(movx4.step.clamps == 0xf);
    CHECK_FALSE(proof->instructions[0].step.clamps);
    CHECK_FALSE(proof->instructions[2].step.clamps);
    // The onset: b·min(4b, 1) equals 4b² only up to b = 0.25 (fx8: 63/255 is the last grid value
    // whose four times stays within 1).
    REQUIRE(movx4.onsets.size() == 1);
    CHECK(movx4.onsets[0].input == "t0");
    CHECK(movx4.onsets[0].above);
    CHECK(movx4.onsets[0].value >= 63.0 / 255 - 1e-6);
    CHECK(movx4.onsets[0].value < 64.0 / 255);
    CHECK(proof->firstClamp() == &proof->instructions[1]);
    // mov_x4's result lies in [0, 1]; r0 = r1·t0 too.
    CHECK(movx4.step.dst[0].lo == 0);
    CHECK(movx4.step.dst[0].hi == 1);

    // `mul_x4 r0, r0, r0` (ps11's earlier adaptive amount) clamps from 4b² > 1, b > 0.5.
    std::optional<Program> q = assembleOk("ps_1_1\ntex t0\nmul_x4 r0, t0, t0\n");
    REQUIRE(q);
    proof = proveRanges(*q, setupFor(*q), diags);
    REQUIRE(proof);
    REQUIRE(proof->instructions[1].onsets.size() == 1);
    CHECK(std::fabs(proof->instructions[1].onsets[0].value - 0.5) < 2.0 / 255);

    // Restricting the texture below the onset makes it range-safe.
    RangeProofSetup safe = setupFor(*p);
    safe.textures[0] = ValueRange::between(0, 0.24, false);
    proof = proveRanges(*p, safe, diags);
    REQUIRE(proof);
    CHECK(proof->firstClamp() == nullptr);
}

TEST_CASE("range proof: _sat cuts, a lerp stays in range, v# and constants are inputs", "[ranges]") {
    std::optional<Program> p =
        assembleOk("ps_1_1\ndef c0, 0.5, 0.5, 0.5, 0.5\ntex t0\nadd_sat r1, t0, v0\nlrp r0, c0, r1, t0\n");
    REQUIRE(p);
    Diagnostics diags;
    std::optional<RangeProof> proof = proveRanges(*p, setupFor(*p), diags);
    REQUIRE(proof);
    REQUIRE(proof->instructions.size() == 3);
    CHECK(proof->instructions[1].step.saturates == 0xf);
    CHECK(proof->instructions[1].step.clamps == 0);
    CHECK(proof->firstClamp() == nullptr);
    // fx8 against float: the bilinear weights (1/256 of the texel range), fx8's rounding of the
    // filtered texel, v0 and the lerp: a few levels, never zero, never huge.
    CHECK(proof->fx8.bounded);
    CHECK(proof->fx8.max() > 0.5);
    CHECK(proof->fx8.max() < 4);
    CHECK(proof->fx12.max() < proof->fx8.max());
}

TEST_CASE("range proof: the bound holds on the corpus and on random programs", "[ranges]") {
    std::mt19937_64 rng(0x5eed2026);
    Tally tally;
    // The corpus: every valid pixel shader of tests/shaders.
    for (const auto& entry : std::filesystem::recursive_directory_iterator(std::filesystem::path(PS11_SOURCE_DIR) / "tests" / "shaders")) {
        if (entry.path().extension() != ".ps11test") continue;
        TestFile file;
        std::vector<TestFileError> errors;
        if (!parseTestFile(slurp(entry.path()), entry.path().string(), file, errors)) continue;
        if (!file.pixelShader.present() || file.pixelShader.expectFail) continue;
        std::optional<Program> p = assembleOk(file.pixelShader.text);
        if (!p) continue;
        checkBound(*p, entry.path().filename().string(), rng, tally);
    }
    const int corpus = tally.programs;
    CHECK(corpus > 100);
    // Random programs of every version.
    for (int i = 0; i < 300; ++i) {
        ps11test::RandomCaseOptions o;
        o.minor = 1 + i % 4;
        const ps11test::RandomCase c = ps11test::randomCase(rng, o);
        std::optional<Program> p = assembleOk(c.shaderText());
        if (!p) continue;
        checkBound(*p, "random " + std::to_string(i) + ":\n" + c.shaderText(), rng, tally);
    }
    CHECK(tally.programs > corpus + 250);
    // Most programs get a finite bound (dependent lookups and bem do not).
    CHECK(tally.bounded > tally.programs);
    WARN("range proof: " << tally.programs << " programs (" << corpus << " corpus), " << tally.bounded
                         << " of " << 2 * tally.programs << " profile bounds finite; measured/bound: worst "
                         << tally.worstRatio << ", mean " << (tally.ratios ? tally.sumRatio / tally.ratios : 0));
}
