// Unit tests for the executor (ps11/executor.h): hand-derived results for every instruction,
// modifier and profile rule of docs/precision.md (arithmetic written out in the comments), a fake
// sampler that records the coordinates it is asked for, and exhaustive checks of the fx8 products
// against roundHalfEven.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/decoded_program.h"
#include "ps11/executor.h"
#include "ps11/validator.h"

using namespace ps11;

namespace {

std::unique_ptr<Executor> build(const std::string& text, Precision prec = Precision::Fx8, float maxValue = 0) {
    Diagnostics diags;
    std::optional<Program> program = parseAssembly(text, "t.psh", {}, diags);
    REQUIRE(program.has_value());
    const bool valid = validate(*program, diags);
    INFO(text << diags.formatAll());
    REQUIRE(valid);
    ExecutorOptions opt;
    opt.precision = prec;
    opt.maxValue = maxValue;
    auto ex = Executor::create(*program, opt, diags);
    INFO(diags.formatAll());
    REQUIRE(ex);
    return ex;
}

struct Pixel {
    std::array<float, 4> v0{0, 0, 0, 0}, v1{0, 0, 0, 0};
    std::array<std::array<float, 4>, 8> tc{};
};

struct Result {
    std::array<float, 4> color{};
    std::array<int32_t, 4> grid{};
    bool killed = false;
    float depth = -1;
};

// Records each request; returns a fixed texel per stage (grid integers in fx, floats otherwise).
class FakeSampler final : public Sampler {
public:
    struct Call {
        int stage, dims;
        std::vector<float> u, v, w;
    };
    std::array<std::array<float, 4>, 8> texel{};
    std::vector<Call> calls;
    bool unitRange = false;  // says so in SampleResult::unitRange (true only for texels in [0, 1])
    void sample(const SampleRequest& req, SampleResult& out) override {
        out.unitRange = unitRange;
        Call c{req.stage, req.dims, {}, {}, {}};
        for (int i = 0; i < req.count; ++i) {
            c.u.push_back(req.u ? req.u[i] : -99.f);
            c.v.push_back(req.v ? req.v[i] : -99.f);
            c.w.push_back(req.w ? req.w[i] : -99.f);
        }
        calls.push_back(c);
        for (int ch = 0; ch < 4; ++ch)
            for (int i = 0; i < req.count; ++i) {
                float t = texel[size_t(req.stage)][size_t(ch)];
                if (out.grid[ch]) out.grid[ch][i] = toGrid(t, req.precision);
                if (out.value[ch]) out.value[ch][i] = t;
            }
    }
    bool hasTexture(int) const override { return true; }
};

std::vector<Result> runPixels(const Executor& ex, const std::vector<Pixel>& px, Sampler& sampler) {
    const int n = int(px.size());
    std::vector<float> col[2][4], tc[8][4], out[4], depth(size_t(n), -1.f);
    std::vector<int32_t> grid[4];
    std::vector<uint8_t> killed(size_t(n), 0);
    PixelInputs in;
    in.count = n;
    for (int c = 0; c < 4; ++c) {
        for (int v = 0; v < 2; ++v) {
            for (const Pixel& p : px) col[v][c].push_back(v == 0 ? p.v0[size_t(c)] : p.v1[size_t(c)]);
            in.color[v][c] = col[v][c].data();
        }
        for (int t = 0; t < 8; ++t) {
            for (const Pixel& p : px) tc[t][c].push_back(p.tc[size_t(t)][size_t(c)]);
            in.texcoord[t][c] = tc[t][c].data();
        }
        out[c].assign(size_t(n), 0);
        grid[c].assign(size_t(n), 0);
    }
    PixelOutputs o;
    for (int c = 0; c < 4; ++c) o.color[c] = out[c].data(), o.grid[c] = grid[c].data();
    o.killed = killed.data();
    o.depth = depth.data();
    std::vector<Result> res(static_cast<size_t>(n));
    for (int off = 0; off < n; off += kMaxSpan) {
        PixelInputs span = in;
        PixelOutputs so = o;
        span.count = std::min(kMaxSpan, n - off);
        for (int c = 0; c < 4; ++c) {
            for (int v = 0; v < 2; ++v) span.color[v][c] += off;
            for (int t = 0; t < 8; ++t) span.texcoord[t][c] += off;
            so.color[c] += off;
            so.grid[c] += off;
        }
        so.killed += off;
        so.depth += off;
        ex.run(span, sampler, so);
    }
    for (int i = 0; i < n; ++i) {
        for (int c = 0; c < 4; ++c) res[size_t(i)].color[size_t(c)] = out[c][size_t(i)], res[size_t(i)].grid[size_t(c)] = grid[c][size_t(i)];
        res[size_t(i)].killed = killed[size_t(i)] != 0;
        res[size_t(i)].depth = depth[size_t(i)];
    }
    return res;
}

Result run1(const Executor& ex, const Pixel& p = {}) {
    NullSampler s;
    return runPixels(ex, {p}, s)[0];
}

using G4 = std::array<int32_t, 4>;
float g8(int n) { return float(n) / 255.0f; }  // an exact fx8 grid value as a colour input

}  // namespace

TEST_CASE("executor: constants clamp to [-1, 1] and round ties to even; def overrides setConstant", "[executor]") {
    auto ex = build("ps_1_1\ndef c0, 2, -3, 0.5, 0\nmov r0, c0\n");
    // 2 → 1 → 255; −3 → −1 → −255; 0.5·255 = 127.5 → 128 (even); 0.
    CHECK(run1(*ex).grid == G4{255, -255, 128, 0});
    ex->setConstant(0, {0.1f, 0.1f, 0.1f, 0.1f});  // def wins
    CHECK(run1(*ex).grid == G4{255, -255, 128, 0});
    auto ex2 = build("ps_1_1\nmov r0, c1\n");
    ex2->setConstant(1, {0.25f, -0.5f, 5.0f, 1.5f / 255.0f});
    // 63.75 → 64; −127.5 → −128 (even); 5 → 1 → 255; 1.5 → 2 (even).
    CHECK(run1(*ex2).grid == G4{64, -128, 255, 2});
    auto ex12 = build("ps_1_1\nmov r0, c1\n", Precision::Fx12);
    ex12->setConstant(1, {0.25f, 1.0f / 32, 3.0f / 32, -5.0f / 32});
    // 1/32·4080 = 127.5 → 128, 382.5 → 382, −637.5 → −638 (ties to even).
    CHECK(run1(*ex12).grid == G4{1020, 128, 382, -638});
}

TEST_CASE("executor: source modifiers in fx8", "[executor]") {
    Pixel p;
    p.v0 = {g8(153), g8(153), g8(153), g8(153)};
    auto check = [&](const char* src, int expect, int minor = 1) {
        std::string text = "ps_1_" + std::to_string(minor) + "\n" + (minor == 4 ? "phase\n" : "") + "mov r0, " + src + "\n";
        auto ex = build(text);
        INFO(src);
        CHECK(run1(*ex, p).grid[0] == expect);
    };
    check("v0", 153);
    check("-v0", -153);
    check("v0_bias", 26);     // k = 306 − 255 = 51 → 51/2 = 25.5 → 26 (even)
    check("-v0_bias", -26);   // −25.5 → −26
    check("v0_bx2", 51);      // k = 612 − 510 = 102 → 51
    check("-v0_bx2", -51);
    check("1-v0", 102);       // k = 510 − 306 = 204 → 102
    check("v0_x2", 306, 4);   // 1_4 (M = 8)
    check("-v0_x2", -306, 4);
}

TEST_CASE("executor: instruction modifiers, _sat, ties to even on shifts", "[executor]") {
    Pixel p;
    p.v0 = {g8(100), g8(1), g8(3), g8(5)};
    auto grid = [&](const std::string& text, Precision prec = Precision::Fx8) { return run1(*build(text, prec), p).grid; };
    CHECK(grid("ps_1_1\nmov_x2 r0, v0\n") == G4{200, 2, 6, 10});
    CHECK(grid("ps_1_1\nmov_x4 r0, v0\n") == G4{255, 4, 12, 20});  // 400 clamps to M = 1
    // _d2: K = 2n over 4: 200/4 = 50, 2/4 = 0.5 → 0, 6/4 = 1.5 → 2, 10/4 = 2.5 → 2.
    CHECK(grid("ps_1_1\nmov_d2 r0, v0\n") == G4{50, 0, 2, 2});
    CHECK(grid("ps_1_4\nphase\nmov_x8 r0, v0\n") == G4{800, 8, 24, 40});
    CHECK(grid("ps_1_4\nphase\nmov_d4 r0, v0\n") == G4{25, 0, 1, 1});  // 0.25 → 0, 0.75 → 1, 1.25 → 1
    CHECK(grid("ps_1_4\nphase\nmov_d8 r0, v0\n") == G4{12, 0, 0, 1});  // 12.5 → 12, 0.375 → 0, 0.625 → 1
    CHECK(grid("ps_1_1\ndef c0, -1, -1, 1, 1\nadd_sat r0, c0, v0\n") == G4{0, 0, 255, 255});
    // fx12 (G = 4080): v0 = 100/255 = 1600/4080; 1/255 = 16 → _d2 of 16·(1,3,5) = 8, 24, 40.
    CHECK(grid("ps_1_1\nmov_d2 r0, v0\n", Precision::Fx12) == G4{800, 8, 24, 40});
    // fx12 ties: c = 1/4080 → n = 1; _d2 → 0.5 → 0; 3 → 1.5 → 2.
    auto ex = build("ps_1_1\nmov_d2 r0, c0\n", Precision::Fx12);
    ex->setConstant(0, {1.0f / 4080, 3.0f / 4080, 5.0f / 4080, 7.0f / 4080});
    CHECK(run1(*ex).grid == G4{0, 2, 2, 4});
}

TEST_CASE("executor: range clamp ±M per profile", "[executor]") {
    Pixel p;
    p.v0 = {1, 1, 1, 1};
    const char* text = "ps_1_1\ndef c0, -1, -1, -1, -1\nadd_x4 r0.rgb, v0, v0\n+sub_x2 r0.a, c0, v0\n";
    // fx8: 8 → 255, −4 → −255.
    CHECK(run1(*build(text), p).grid == G4{255, 255, 255, -255});
    CHECK(run1(*build(text, Precision::Fx12), p).grid == G4{4080, 4080, 4080, -4080});
    CHECK(run1(*build(text, Precision::Float), p).color == std::array<float, 4>{1, 1, 1, -1});
    CHECK(run1(*build(text, Precision::Ideal), p).color == std::array<float, 4>{8, 8, 8, -4});
    // 1_4: M = 8 by default: 2040; explicit M = 2 → 510.
    const char* t14 = "ps_1_4\ndef c0, 1, 1, 1, 1\nadd_x8 r0, c0, c0\n";
    CHECK(run1(*build(t14)).grid == G4{2040, 2040, 2040, 2040});
    CHECK(run1(*build(t14, Precision::Fx8, 2.0f)).grid == G4{510, 510, 510, 510});
    CHECK(run1(*build(t14, Precision::Float)).color == std::array<float, 4>{8, 8, 8, 8});
    CHECK(run1(*build(t14, Precision::Ideal)).color == std::array<float, 4>{16, 16, 16, 16});
    CHECK(run1(*build("ps_1_4\ndef c0, 1, 1, 1, 1\nadd_x8_sat r0, c0, c0\n", Precision::Ideal)).color ==
          std::array<float, 4>{1, 1, 1, 1});
}

TEST_CASE("executor: add sub mul mad lrp dp3 dp4 in fx8", "[executor]") {
    Pixel p;
    p.v0 = {g8(128), g8(200), g8(10), g8(255)};
    p.v1 = {g8(51), g8(100), g8(250), g8(3)};
    auto grid = [&](const std::string& body, int minor = 1) {
        return run1(*build("ps_1_" + std::to_string(minor) + "\n" + body), p).grid;
    };
    CHECK(grid("add r0, v0, v1\n") == G4{179, 255, 255, 255});
    CHECK(grid("sub r0, v0, v1\n") == G4{77, 100, -240, 252});
    // mul: n0·n1/255: 6528/255 = 25.6 → 26; 20000/255 = 78.43 → 78; 2500/255 = 9.80 → 10; 3.
    CHECK(grid("mul r0, v0, v1\n") == G4{26, 78, 10, 3});
    // mad with c0 = 0.2 (51): 25.6 + 51 = 76.6 → 77; 129.43 → 129; 60.80 → 61; 54.
    CHECK(grid("def c0, 0.2, 0.2, 0.2, 0.2\nmad r0, v0, v1, c0\n") == G4{77, 129, 61, 54});
    // lrp f = v0, a = c0 = 1 (255), b = c1 = 0.2 (51): n = f·255/255 + (255 − f)·51/255
    // r: 128 + 127·0.2 = 153.4 → 153; g: 200 + 11 = 211; b: 10 + 49 = 59; a: 255.
    CHECK(grid("def c0, 1, 1, 1, 1\ndef c1, 0.2, 0.2, 0.2, 0.2\nlrp r0, v0, c0, c1\n") == G4{153, 211, 59, 255});
    // dp3 v0·c0 with c0 = 0.5 (128): (128 + 200 + 10)·128/255 = 169.66 → 170, replicated to a too.
    CHECK(grid("def c0, 0.5, 0.5, 0.5, 0.5\ndp3 r0, v0, c0\n") == G4{170, 170, 170, 170});
    // dp3 into .rgb keeps a from the previous write.
    CHECK(grid("def c0, 0.5, 0.5, 0.5, 0.5\nmov r0, v1\ndp3 r0.rgb, v0, c0\n") == G4{170, 170, 170, 3});
    // dp4_d2 (1_2): (128 + 200 + 10 + 255)·128/510 = 148.86 → 149.
    CHECK(grid("def c0, 0.5, 0.5, 0.5, 0.5\ndp4_d2 r0, v0, c0\n", 2) == G4{149, 149, 149, 149});
    // dp3 with _bx2: k = 4n − 510: (2, 290, −470)·(−306, −110, 490) = −612 − 31900 − 230300
    // = −262812; /1020 = −257.66 → clamped to −255; with _d2: /2040 = −128.83 → −129.
    CHECK(grid("dp3 r0, v0_bx2, v1_bx2\n") == G4{-255, -255, -255, -255});
    CHECK(grid("dp3_d2 r0, v0_bx2, v1_bx2\n") == G4{-129, -129, -129, -129});
    // mul tie: v0_bias (k = 1) · v1 (n = 255 → k = 510): 510/1020 = 0.5 → 0; k = 3: 1.5 → 2.
    Pixel q;
    q.v0 = {g8(128), g8(129), 0, 0};
    q.v1 = {1, 1, 0, 0};
    CHECK(run1(*build("ps_1_1\nmul r0, v0_bias, v1\n"), q).grid == G4{0, 2, 0, 0});
}

TEST_CASE("executor: masks, co-issue reads before writes, cnd, cmp", "[executor]") {
    auto grid = [](const std::string& text) { return run1(*build(text)).grid; };
    CHECK(grid("ps_1_1\ndef c0, 0.2, 0.4, 0.6, 0.8\ndef c1, 1, 1, 1, 1\nmov r0, c0\nmov r0.a, c1\n") ==
          G4{51, 102, 153, 255});
    // Pair: the .a member reads the old r0.b (0.6 → 153), not the new 255.
    CHECK(grid("ps_1_1\ndef c0, 0.2, 0.4, 0.6, 0.8\ndef c1, 1, 1, 1, 1\nmov r0, c0\nmov r0.rgb, c1\n+mov r0.a, r0.b\n") ==
          G4{255, 255, 255, 153});
    // Reverse order: rgb reads the old r0.a (0.8 → 204).
    CHECK(grid("ps_1_1\ndef c0, 0.2, 0.4, 0.6, 0.8\ndef c1, 1, 1, 1, 1\nmov r0, c0\nmov r0.a, c1\n+mov r0.rgb, r0.a\n") ==
          G4{204, 204, 204, 255});
    // cnd 1_1: r0.a = 0.8 > 0.5 selects c1 for every component; r0.a = 0.5 is not > 0.5.
    const char* cnd11 = "ps_1_1\ndef c0, %s\ndef c1, 0.2, 0.4, 0.6, 0.8\ndef c2, 1, 0, 1, 0\nmov r0, c0\ncnd r0, r0.a, c1, c2\n";
    char buf[256];
    std::snprintf(buf, sizeof buf, cnd11, "0, 0, 0, 0.8");
    CHECK(grid(buf) == G4{51, 102, 153, 204});
    std::snprintf(buf, sizeof buf, cnd11, "1, 1, 1, 0.498");  // 126.99 → 127: k = 254 ≤ 255
    CHECK(grid(buf) == G4{255, 0, 255, 0});
    // cnd 1_4 per component: s0 = (0.6, 0.498 (127), 0.4, 1) → (a, b, b, a).
    CHECK(grid("ps_1_4\ndef c0, 0.6, 0.498, 0.4, 1\ndef c1, 0.2, 0.4, 0.6, 0.8\ndef c2, 1, 0, 1, 0\n"
               "mov r1, c0\nmov r2, c2\ncnd r0, r1, c1, r2\n") == G4{51, 0, 255, 204});
    // cmp (1_2): s0 = (0, −0.2, 0.3, −1) ≥ 0 → (a, b, a, b).
    CHECK(grid("ps_1_2\ndef c0, 0, -0.2, 0.3, -1\ndef c1, 0.2, 0.4, 0.6, 0.8\ndef c2, 1, 0, 1, 0\n"
               "mov r1, c0\ncmp r0, r1, c1, c2\n") == G4{51, 0, 153, 0});
    // 1_4 arbitrary mask .rb
    CHECK(grid("ps_1_4\ndef c0, 0.2, 0.4, 0.6, 0.8\ndef c1, 1, 1, 1, 1\nmov r0, c1\nmov r0.rb, c0\n") ==
          G4{51, 255, 153, 255});
}

TEST_CASE("executor: float and ideal arithmetic, no FMA contraction", "[executor]") {
    Pixel p;
    p.v0 = {0.3f, 0.6f, 0.9f, 1};
    p.v1 = {0.5f, 0.25f, 0.125f, 0};
    auto col = [&](const std::string& text, Precision prec = Precision::Float) { return run1(*build(text, prec), p).color; };
    std::array<float, 4> e{};
    for (int c = 0; c < 4; ++c) e[size_t(c)] = p.v0[size_t(c)] * p.v1[size_t(c)];
    CHECK(col("ps_1_1\nmul r0, v0, v1\n") == e);
    for (int c = 0; c < 4; ++c) e[size_t(c)] = 2.0f * p.v0[size_t(c)] - 1.0f;
    CHECK(col("ps_1_1\nmov r0, v0_bx2\n") == e);
    // a = 1 − 2^-13: a·a = 1 − 2^-12 + 2^-26 rounds to 1 − 2^-12, so a·a − (1 − 2^-12) = 0 without
    // FMA (2^-26 with a fused multiply-add).
    Pixel q;
    const float a = 1.0f - std::ldexp(1.0f, -13), b = 1.0f - std::ldexp(1.0f, -12);
    q.v0 = {a, a, a, a};
    q.v1 = {b, b, b, b};
    CHECK(run1(*build("ps_1_1\nmad r0, v0, v0, -v1\n", Precision::Ideal), q).color[0] == 0.0f);
    // lrp as b + f·(a − b); dp3 ((r + g) + b).
    const float f = 0.3f, av = 0.6f, bv = 0.5f;
    CHECK(col("ps_1_4\ndef c0, 0.6, 0.6, 0.6, 0.6\ndef c1, 0.5, 0.5, 0.5, 0.5\nphase\nlrp r0, v0, c0, c1\n")[0] ==
          bv + f * (av - bv));
    CHECK(col("ps_1_1\ndp3 r0, v0, v1\n")[3] == (0.3f * 0.5f + 0.6f * 0.25f) + 0.9f * 0.125f);
}

TEST_CASE("executor: a sampled texel is clamped to ±MaxValue even when the sampler says [0, 1]", "[executor]") {
    // unitRange skips the clamp only where it cannot change a value (M >= 1); with M = 0.5 a
    // white texel still becomes 0.5 (fx8 128, fx12 2040, float 0.5), with M = 1 it stays 1.
    FakeSampler s;
    s.texel[0] = {1, 1, 0.25f, 0};
    for (bool unit : {false, true}) {
        s.unitRange = unit;
        INFO("unitRange " << unit);
        CHECK(runPixels(*build("ps_1_1\ntex t0\nmov r0, t0\n", Precision::Fx8, 0.5f), {Pixel{}}, s)[0].grid ==
              G4{128, 128, 64, 0});
        CHECK(runPixels(*build("ps_1_4\ntexld r0, t0\n", Precision::Fx12, 0.5f), {Pixel{}}, s)[0].grid ==
              G4{2040, 2040, 1020, 0});
        CHECK(runPixels(*build("ps_1_4\ntexld r0, t0\n", Precision::Fx12, 1.0f), {Pixel{}}, s)[0].grid ==
              G4{4080, 4080, 1020, 0});
        CHECK(runPixels(*build("ps_1_1\ntex t0\nmov r0, t0\n", Precision::Float, 0.5f), {Pixel{}}, s)[0].color ==
              std::array<float, 4>{0.5f, 0.5f, 0.25f, 0});
    }
}

TEST_CASE("executor: texcoord, tex with projection, texkill", "[executor]") {
    FakeSampler s;
    Pixel p;
    p.tc[0] = {1.5f, -0.2f, 0.5f, 7};
    auto ex = build("ps_1_1\ntexcoord t0\nmov r0, t0\n");
    // sat then round: 255, 0, 127.5 → 128, w = 1 → 255.
    CHECK(runPixels(*ex, {p}, s)[0].grid == G4{255, 0, 128, 255});

    p.tc[1] = {0.25f, 0.5f, 0.75f, 2};
    auto tex = build("ps_1_1\ntex t1\nmov r0, t1\n");
    s.texel[1] = {0.2f, 0.4f, 0.6f, 1};
    CHECK(runPixels(*tex, {p}, s)[0].grid == G4{51, 102, 153, 255});
    REQUIRE(s.calls.size() == 1);
    CHECK(s.calls[0].stage == 1);
    CHECK(s.calls[0].u[0] == 0.25f);
    CHECK(s.calls[0].v[0] == 0.5f);
    // D3DTTFF_PROJECTED resolves against the set's components and the texture's dimensions
    // (projectionDivisor; Wine's projected_textures_test): TC1 = (0.25, 0.5, 0.75, 2).
    struct Case {
        uint32_t flags;
        uint8_t components, dims;
        float div;
    } cases[] = {
        {kTtffProjected | 4, 4, 2, 2},       {kTtffProjected, 4, 2, 2},          {kTtffProjected | 3, 4, 2, 0.75f},
        {kTtffProjected | 2, 4, 2, 1},       {kTtffProjected | 1, 4, 2, 1},      {4, 4, 2, 1},
        {0xffffffffu, 4, 2, 2},              {0xffffffffu, 3, 2, 0.75f},         {kTtffProjected, 3, 2, 0.75f},
        {kTtffProjected | 3, 2, 2, 1},       {kTtffProjected | 4, 3, 2, 0.75f},  {kTtffProjected | 3, 4, 3, 1},
        {kTtffProjected | 4, 4, 3, 2},       {kTtffProjected | 0x2004, 4, 2, 2},
    };
    for (const Case& c : cases) {
        StageState ss;
        ss.transformFlags = c.flags;
        ss.coordComponents = c.components;
        ss.textureDimensions = c.dims;
        tex->setStageState(1, ss);
        s.calls.clear();
        runPixels(*tex, {p}, s);
        INFO(c.flags << " components " << int(c.components) << " dims " << int(c.dims));
        CHECK(s.calls[0].u[0] == 0.25f / c.div);
        CHECK(s.calls[0].v[0] == 0.5f / c.div);
    }

    auto kill = build("ps_1_1\ntexkill t0\nmov r0, c0\n");
    Pixel a, b, c;
    a.tc[0] = {0.1f, -0.1f, 0.2f, 1};
    b.tc[0] = {0.1f, 0.1f, 0.1f, -5};  // q ignored
    c.tc[0] = {0.1f, 0.1f, -0.001f, 1};
    auto r = runPixels(*kill, {a, b, c}, s);
    CHECK(r[0].killed);
    CHECK_FALSE(r[1].killed);
    CHECK(r[2].killed);
}

TEST_CASE("executor: texbem, texbeml, texreg2*, texdp3, texdp3tex", "[executor]") {
    FakeSampler s;
    s.texel[0] = {0.2f, 0.4f, 0.6f, 0.8f};  // 51, 102, 153, 204
    s.texel[1] = {0.5f, 1.0f, 0.0f, 0.25f};  // 128, 255, 0, 64
    Pixel p;
    p.tc[1] = {0.1f, 0.3f, 0, 1};
    StageState ss;
    ss.bumpMat = {0.5f, 0.25f, -0.5f, 1.0f};  // M00, M01, M10, M11
    ss.lumScale = 0.5f;
    ss.lumOffset = 0.1f;
    auto bem = build("ps_1_1\ntex t0\ntexbem t1, t0\nmov r0, t1\n");
    bem->setStageState(1, ss);
    runPixels(*bem, {p}, s);
    const float r = 51.0f / 255.0f, g = 102.0f / 255.0f;
    CHECK(s.calls[1].u[0] == 0.1f + 0.5f * r + -0.5f * g);
    CHECK(s.calls[1].v[0] == 0.3f + 0.25f * r + 1.0f * g);

    auto beml = build("ps_1_1\ntex t0\ntexbeml t1, t0\nmov r0, t1\n");
    beml->setStageState(1, ss);
    // L = 0.6·0.5 + 0.1 = 0.4 (b = 153/255); 128·0.4 = 51.2 → 51, 255·0.4 = 102, 0, 64·0.4 = 25.6 → 26.
    CHECK(runPixels(*beml, {p}, s)[0].grid == G4{51, 102, 0, 26});
    // Not clamped: offset 2 gives L = 2.3 → 128·2.3 = 294.4 → 255 only by the range clamp.
    ss.lumOffset = 2.0f;
    beml->setStageState(1, ss);
    CHECK(runPixels(*beml, {p}, s)[0].grid[0] == 255);

    s.calls.clear();
    runPixels(*build("ps_1_1\ntex t0\ntexreg2ar t1, t0\nmov r0, t1\n"), {p}, s);
    CHECK(s.calls[1].u[0] == 204.0f / 255.0f);
    CHECK(s.calls[1].v[0] == 51.0f / 255.0f);
    CHECK(s.calls[1].w[0] == 51.0f / 255.0f);
    s.calls.clear();
    runPixels(*build("ps_1_1\ntex t0\ntexreg2gb t1, t0\nmov r0, t1\n"), {p}, s);
    CHECK(s.calls[1].u[0] == 102.0f / 255.0f);
    CHECK(s.calls[1].v[0] == 153.0f / 255.0f);
    CHECK(s.calls[1].w[0] == 153.0f / 255.0f);
    s.calls.clear();
    runPixels(*build("ps_1_2\ntex t0\ntexreg2rgb t1, t0\nmov r0, t1\n"), {p}, s);
    CHECK(s.calls[1].w[0] == 153.0f / 255.0f);

    // texdp3: TC1.xyz · t0.rgb = 0.1·0.2 + 0.3·0.4 = 0.14 → 35.7 → 36 in all four channels.
    p.tc[1] = {0.1f, 0.3f, 0, 1};
    CHECK(runPixels(*build("ps_1_2\ntex t0\ntexdp3 t1, t0\nmov r0, t1\n"), {p}, s)[0].grid == G4{36, 36, 36, 36});
    s.calls.clear();
    runPixels(*build("ps_1_2\ntex t0\ntexdp3tex t1, t0\nmov r0, t1\n"), {p}, s);
    CHECK(s.calls[1].u[0] == Approx(0.14f));
    CHECK(s.calls[1].v[0] == 0.0f);
}

TEST_CASE("executor: texm3x2, texm3x3 families, spec/vspec reflection, depth", "[executor]") {
    FakeSampler s;
    s.texel[0] = {1, 0, 0, 1};  // T[0].rgb = (1, 0, 0): each row dot = TC.x
    Pixel p;
    p.tc[1] = {0.5f, 9, 9, 1};
    p.tc[2] = {0.25f, 9, 9, 0};
    p.tc[3] = {1.0f, 9, 9, 1};
    runPixels(*build("ps_1_1\ntex t0\ntexm3x2pad t1, t0\ntexm3x2tex t2, t0\nmov r0, t2\n"), {p}, s);
    CHECK(s.calls.back().stage == 2);
    CHECK(s.calls.back().u[0] == 0.5f);
    CHECK(s.calls.back().v[0] == 0.25f);

    // texm3x2depth: z/w = 0.5/0.25 = 2 → clamped to 1; with TC2.x = 2: 0.25; w = 0 → 1.
    auto depth = build("ps_1_3\ntex t0\ntexm3x2pad t1, t0\ntexm3x2depth t2, t0\nmov r0, t0\n");
    REQUIRE(depth->writesDepth());
    Pixel q = p, z = p;
    q.tc[2][0] = 2.0f;
    z.tc[2][0] = 0.0f;
    auto d = runPixels(*depth, {p, q, z}, s);
    CHECK(d[0].depth == 1.0f);
    CHECK(d[1].depth == 0.25f);
    CHECK(d[2].depth == 1.0f);

    s.calls.clear();
    runPixels(*build("ps_1_1\ntex t0\ntexm3x3pad t1, t0\ntexm3x3pad t2, t0\ntexm3x3tex t3, t0\nmov r0, t3\n"), {p}, s);
    CHECK(s.calls.back().stage == 3);
    CHECK(s.calls.back().u[0] == 0.5f);
    CHECK(s.calls.back().v[0] == 0.25f);
    CHECK(s.calls.back().w[0] == 1.0f);
    // texm3x3 writes (N, 1): 127.5 → 128, 63.75 → 64, 255, 255.
    CHECK(runPixels(*build("ps_1_2\ntex t0\ntexm3x3pad t1, t0\ntexm3x3pad t2, t0\ntexm3x3 t3, t0\nmov r0, t3\n"), {p}, s)[0]
              .grid == G4{128, 64, 255, 255});

    // spec: N = (0, 0, 1), E = (1, 0, 1): N·E = 1, N·N = 1 → R = 2·(0, 0, 1) − (1, 0, 1) = (−1, 0, 1).
    Pixel n = p;
    n.tc[1][0] = 0;
    n.tc[2][0] = 0;
    n.tc[3][0] = 1;
    auto spec = build("ps_1_1\ndef c0, 1, 0, 1, 0\ntex t0\ntexm3x3pad t1, t0\ntexm3x3pad t2, t0\n"
                      "texm3x3spec t3, t0, c0\nmov r0, t3\n");
    s.calls.clear();
    runPixels(*spec, {n}, s);
    CHECK(s.calls.back().u[0] == -1.0f);
    CHECK(s.calls.back().v[0] == 0.0f);
    CHECK(s.calls.back().w[0] == 1.0f);
    // N = (0, 0, 2), E = (1, 0, 1): 2·2/4·(0, 0, 2) − E = (−1, 0, 1): not normalised, same here;
    // N = 0 gives −E.
    Pixel zero = n;
    zero.tc[3][0] = 0;
    s.calls.clear();
    runPixels(*spec, {zero}, s);
    CHECK(s.calls.back().u[0] == -1.0f);
    CHECK(s.calls.back().w[0] == -1.0f);
    // vspec: E from the q components (1, 0, 1) → same R.
    n.tc[1][3] = 1;
    n.tc[2][3] = 0;
    n.tc[3][3] = 1;
    s.calls.clear();
    runPixels(*build("ps_1_1\ntex t0\ntexm3x3pad t1, t0\ntexm3x3pad t2, t0\ntexm3x3vspec t3, t0\nmov r0, t3\n"), {n}, s);
    CHECK(s.calls.back().u[0] == -1.0f);
    CHECK(s.calls.back().v[0] == 0.0f);
    CHECK(s.calls.back().w[0] == 1.0f);
}

TEST_CASE("executor: ps_1_4 texld forms, texcrd, texdepth, bem, phase", "[executor]") {
    FakeSampler s;
    Pixel p;
    p.tc[0] = {0.5f, 0.25f, 9.0f, 2.0f};
    runPixels(*build("ps_1_4\ntexld r0, t0_dw.xyw\n"), {p}, s);
    CHECK(s.calls.back().u[0] == 0.25f);
    CHECK(s.calls.back().v[0] == 0.125f);
    Pixel zw = p;
    zw.tc[0][3] = 0;  // zero divisor gives 1.0
    runPixels(*build("ps_1_4\ntexld r0, t0_dw.xyw\n"), {zw}, s);
    CHECK(s.calls.back().u[0] == 1.0f);
    CHECK(s.calls.back().v[0] == 1.0f);
    runPixels(*build("ps_1_4\ntexld r0, t0.xyw\n"), {p}, s);
    CHECK(s.calls.back().w[0] == 2.0f);
    runPixels(*build("ps_1_4\ntexld r0, t0\n"), {p}, s);
    CHECK(s.calls.back().w[0] == 9.0f);
    // _dz on r#: r1 = texcrd (0.5, 0.25, 0.5) → (1, 0.5); z = 0 → (1, 1).
    Pixel dz;
    dz.tc[0] = {0.5f, 0.25f, 0.5f, 1};
    auto dzx = build("ps_1_4\ntexcrd r1.rgb, t0\nphase\ntexld r0, r1_dz\n");
    runPixels(*dzx, {dz}, s);
    CHECK(s.calls.back().u[0] == 128.0f / 128.0f);   // grid 128/128
    CHECK(s.calls.back().v[0] == 64.0f / 128.0f);
    dz.tc[0][2] = 0;
    runPixels(*dzx, {dz}, s);
    CHECK(s.calls.back().u[0] == 1.0f);
    CHECK(s.calls.back().v[0] == 1.0f);

    // texcrd: no [0, 1] clamp, but ±M (8): 3 → 765, −9 → −2040, 0.5 → 128 (even), a untouched.
    Pixel c;
    c.tc[0] = {3.0f, -9.0f, 0.5f, 1};
    CHECK(runPixels(*build("ps_1_4\ndef c0, 0, 0, 0, 0.2\nmov r0, c0\nphase\ntexcrd r0.rgb, t0\nmov r0.a, c0\n"), {c}, s)[0].grid ==
          G4{765, -2040, 128, 51});
    // texcrd _dw.xyw: (x/w, y/w, w): (0.25, 0.125, 2) → 64 (63.75), 32 (31.875), 510.
    CHECK(runPixels(*build("ps_1_4\ntexcrd r0.rgb, t0_dw.xyw\n"), {p}, s)[0].grid[0] == 64);
    CHECK(runPixels(*build("ps_1_4\ntexcrd r0.rgb, t0_dw.xyw\n"), {p}, s)[0].grid[2] == 510);

    // texdepth: r5 = (0.2, 0.8) → 51/204 = 0.25; g = 0 → 1; r/g = 2 → 1.
    auto td = build("ps_1_4\ntexcrd r5.rgb, t0\nphase\ntexdepth r5\nmov r0, c0\n");
    REQUIRE(td->writesDepth());
    Pixel a, b, e;
    a.tc[0] = {0.2f, 0.8f, 0, 0};
    b.tc[0] = {0.2f, 0.0f, 0, 0};
    e.tc[0] = {0.8f, 0.4f, 0, 0};
    auto dd = runPixels(*td, {a, b, e}, s);
    CHECK(dd[0].depth == 0.25f);
    CHECK(dd[1].depth == 1.0f);
    CHECK(dd[2].depth == 1.0f);

    // bem r1.rg, r0, r2 with the matrix of stage 1: r0 = (0.2, 0.4), r2 = (0.5, 0.25);
    // r = 51/255 + 0.5·128/255 + (−0.5)·64/255 → 51 + 64 − 32 = 83; g = 102 + 0.25·128 + 64 = 198.
    auto bem = build("ps_1_4\ntexcrd r0.rgb, t0\ntexcrd r2.rgb, t1\ntexcrd r1.rgb, t2\nbem r1.rg, r0, r2\nphase\ntexld r3, r1\nmov r0, r3\n");
    StageState ss;
    ss.bumpMat = {0.5f, 0.25f, -0.5f, 1.0f};
    bem->setStageState(1, ss);
    Pixel bp;
    bp.tc[0] = {0.2f, 0.4f, 0, 0};
    bp.tc[1] = {128.0f / 255, 64.0f / 255, 0, 0};
    s.calls.clear();
    runPixels(*bem, {bp}, s);
    CHECK(s.calls.back().u[0] == 83.0f / 255.0f);
    CHECK(s.calls.back().v[0] == 198.0f / 255.0f);
}

TEST_CASE("executor: fx8 products match roundHalfEven exhaustively", "[executor]") {
    // Every n0, n1 in [0, 255]: mul = rhe(n0·n1, 255); mad with c = 0.2 (51) = rhe(n0·n1 + 51·255, 255);
    // lrp with b = 51: rhe(n0·(n1 − 51)·4 + 510·102, 1020) = rhe(n0·(n1 − 51) + 51·255, 255).
    std::vector<Pixel> px;
    for (int a = 0; a < 256; ++a)
        for (int b = 0; b < 256; ++b) {
            Pixel p;
            p.v0 = {g8(a), g8(a), g8(a), g8(a)};
            p.v1 = {g8(b), g8(b), g8(b), g8(b)};
            px.push_back(p);
        }
    NullSampler s;
    auto res = runPixels(*build("ps_1_1\ndef c0, 0.2, 0.2, 0.2, 0.2\nmul r0.rgb, v0, v1\n+mad r0.a, v0, v1, c0\n"), px, s);
    auto lrp = runPixels(*build("ps_1_1\ndef c0, 0.2, 0.2, 0.2, 0.2\nlrp r0, v0, v1, c0\n"), px, s);
    auto bx2 = runPixels(*build("ps_1_1\nmul_x2 r0, v0_bx2, v1_bias\n"), px, s);
    int bad = 0;
    for (int a = 0; a < 256; ++a)
        for (int b = 0; b < 256; ++b) {
            const Result& r = res[size_t(a * 256 + b)];
            bad += r.grid[0] != roundHalfEven(a * b, 255);
            bad += r.grid[3] != std::min<int64_t>(255, roundHalfEven(a * b + 51 * 255, 255));
            bad += lrp[size_t(a * 256 + b)].grid[0] != roundHalfEven(a * (b - 51) + 51 * 255, 255);
            // (4a − 510)(2b − 255)·2/1020, clamped to ±255.
            int64_t x = roundHalfEven(int64_t(4 * a - 510) * (2 * b - 255) * 2, 1020);
            bad += bx2[size_t(a * 256 + b)].grid[0] != std::clamp<int64_t>(x, -255, 255);
        }
    CHECK(bad == 0);
}

TEST_CASE("executor: E40xx diagnostics", "[executor]") {
    Diagnostics diags;
    std::optional<Program> program = parseAssembly("ps_1_1\nmov r0, v0\n", "t.psh", {}, diags);
    REQUIRE(program);
    ExecutorOptions bad;
    bad.maxValue = -1;
    CHECK_FALSE(Executor::create(*program, bad, diags));
    CHECK(diags.has("E4003"));
    bad.maxValue = 1e7f;
    CHECK_FALSE(Executor::create(*program, bad, diags));
    Program v = *program;
    v.version.minor = 5;
    CHECK_FALSE(Executor::create(v, {}, diags));
    CHECK(diags.has("E4001"));
    Program op = *program;
    op.instructions[0].info = &opcodeTable()[size_t(std::find_if(opcodeTable().begin(), opcodeTable().end(),
                                                                 [](const OpcodeInfo& i) {
                                                                     return i.opcode == Opcode::TexM3x3Diff;
                                                                 }) -
                                                    opcodeTable().begin())];
    CHECK_FALSE(Executor::create(op, {}, diags));
    CHECK(diags.has("E4002"));
}

TEST_CASE("executor: r0's channels read before written, or never written, read 0 whatever ran before", "[executor]") {
    // A program leaving r0 = 1 in this thread's run state runs first, then the program under test;
    // the channels it reads before writing (or never writes) must start at 0, and only those are
    // preset (decided once per program: exec::r0PresetChannels). The validator refuses reads of
    // unwritten channels (D3D does too), so those programs are run unvalidated: the executor
    // still defines them.
    auto program = [](const std::string& text) {
        Diagnostics diags;
        std::optional<Program> p = parseAssembly(text, "t.psh", {}, diags);
        REQUIRE(p.has_value());
        return *p;
    };
    struct Case {
        const char* text;
        bool valid;
        uint8_t preset;
        std::array<float, 4> want;  // v0 = (0.2, 0.4, 0.6, 0.8)
    };
    const Case cases[] = {
        {"ps_1_1\nmov r0, v0\n", true, 0x0, {0.2f, 0.4f, 0.6f, 0.8f}},
        {"ps_1_1\nmov r0.rgb, v0\n", true, 0x8, {0.2f, 0.4f, 0.6f, 0}},
        {"ps_1_4\nmov r0.rgb, v0\nadd r0.a, r0.r, v0\n", true, 0x0, {0.2f, 0.4f, 0.6f, 1.0f}},
        {"ps_1_4\nmov r0.rg, v0\nmov r0.ba, r0.r\n", true, 0x0, {0.2f, 0.4f, 0.2f, 0.2f}},
        {"ps_1_1\nmov r0.a, v0\nadd r0.rgb, r0, v0\n", false, 0x7, {0.2f, 0.4f, 0.6f, 0.8f}},
        // The pair's second member reads r0.b before the first member's result lands.
        {"ps_1_1\nmov r0.rgb, v0\n+mov r0.a, r0.b\n", false, 0x4, {0.2f, 0.4f, 0.6f, 0}},
        {"ps_1_1\nmov r0.a, v0\n+mov r0.rgb, r0.a\n", false, 0x8, {0, 0, 0, 0.8f}},
    };
    for (Precision prec : {Precision::Fx8, Precision::Fx12, Precision::Float, Precision::Ideal}) {
        for (const Case& c : cases) {
            INFO(precisionName(prec) << "\n" << c.text);
            const Program p = program(c.text);
            Diagnostics diags;
            CHECK(validate(p, diags) == c.valid);
            ExecutorOptions opt;
            opt.precision = prec;
            exec::DecodedProgram d;
            REQUIRE(exec::decodeProgram(p, opt, diags, d));
            CHECK(exec::r0PresetChannels(d.ops) == c.preset);
            auto ones = build("ps_1_1\ndef c0, 1, 1, 1, 1\nmov r0, c0\n", prec);
            auto ex = Executor::create(p, opt, diags);
            REQUIRE(ex);
            Pixel px;
            px.v0 = {0.2f, 0.4f, 0.6f, 0.8f};
            const std::vector<Pixel> span(40, px);
            NullSampler s;
            REQUIRE(runPixels(*ones, span, s)[0].color[0] == 1.0f);
            const Result r = runPixels(*ex, span, s)[39];
            for (size_t ch = 0; ch < 4; ++ch) CHECK(r.color[ch] == Approx(c.want[ch]).margin(1.0 / 255));
        }
    }
}
