// The one SIMD dispatch (ps11/simd_dispatch.h): PS11_SIMD's rule, the override, each family's
// tables per level, and the families without a cross-level test of their own, each run at every
// level this CPU runs and compared bit for bit: the float arithmetic (generic executor, float
// and ideal profiles) and the output merger's half store. The executor's fx8 kernels, the fast
// sampler and the aligned-pass path are compared across levels by test_executor_fast.cpp,
// test_sampler_fast.cpp and test_aligned_pass.cpp (and the half store once more by
// test_output_merger_float.cpp, against format.cpp).
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "emu/aligned_float_kernels.h"
#include "emu/aligned_pass_kernels.h"
#include "emu/format.h"
#include "emu/output_merger.h"
#include "emu/output_merger_kernels.h"
#include "emu/resources.h"
#include "executor_random_programs.h"
#include "ps11/cpu_features.h"
#include "ps11/executor.h"
#include "ps11/executor_fast.h"
#include "ps11/executor_internal.h"
#include "ps11/precision.h"
#include "ps11/simd_dispatch.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler_fast.h"
#include "simd_levels.h"

using ps11::SimdLevel;

namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("simd dispatch: level names", "[simd]") {
    CHECK(std::string(ps11::simdLevelName(SimdLevel::Baseline)) == "baseline");
    CHECK(std::string(ps11::simdLevelName(SimdLevel::Avx2)) == "avx2");
    CHECK(std::string(ps11::simdLevelName(SimdLevel::Avx512)) == "avx512");
    CHECK(ps11::parseSimdLevel("baseline") == SimdLevel::Baseline);
    CHECK(ps11::parseSimdLevel("avx2") == SimdLevel::Avx2);
    CHECK(ps11::parseSimdLevel("avx512") == SimdLevel::Avx512);
    CHECK_FALSE(ps11::parseSimdLevel("AVX2"));
    CHECK_FALSE(ps11::parseSimdLevel("sse2"));
    CHECK_FALSE(ps11::parseSimdLevel(""));
}

TEST_CASE("simd dispatch: PS11_SIMD's rule, bad values and levels the CPU cannot run", "[simd]") {
    std::string error = "stale";
    // Unset or empty: the best level, silently.
    CHECK(ps11::simdLevelFromEnv(nullptr, SimdLevel::Avx2, error) == SimdLevel::Avx2);
    CHECK(error.empty());
    CHECK(ps11::simdLevelFromEnv("", SimdLevel::Baseline, error) == SimdLevel::Baseline);
    CHECK(error.empty());
    // A level the CPU runs.
    CHECK(ps11::simdLevelFromEnv("baseline", SimdLevel::Avx2, error) == SimdLevel::Baseline);
    CHECK(error.empty());
    CHECK(ps11::simdLevelFromEnv("avx2", SimdLevel::Avx2, error) == SimdLevel::Avx2);
    CHECK(error.empty());
    CHECK(ps11::simdLevelFromEnv("avx512", SimdLevel::Avx512, error) == SimdLevel::Avx512);
    CHECK(error.empty());
    CHECK(ps11::simdLevelFromEnv("avx2", SimdLevel::Avx512, error) == SimdLevel::Avx2);
    CHECK(error.empty());
    // An unknown value: the best level, and a message naming the variable and the value.
    CHECK(ps11::simdLevelFromEnv("avx1024", SimdLevel::Avx2, error) == SimdLevel::Avx2);
    INFO(error);
    CHECK(contains(error, "PS11_SIMD=avx1024"));
    CHECK(contains(error, "unknown SIMD level"));
    CHECK(contains(error, "using avx2"));
    CHECK(ps11::simdLevelFromEnv("Baseline", SimdLevel::Baseline, error) == SimdLevel::Baseline);
    CHECK(contains(error, "PS11_SIMD=Baseline"));
    // Avx2 on a CPU without it: Baseline, and a message.
    CHECK(ps11::simdLevelFromEnv("avx2", SimdLevel::Baseline, error) == SimdLevel::Baseline);
    CHECK(contains(error, "PS11_SIMD=avx2"));
    CHECK(contains(error, "cannot run avx2"));
    CHECK(contains(error, "using baseline"));
    // Avx512 on an Avx2 CPU: Avx2, and a message naming what it lacks.
    CHECK(ps11::simdLevelFromEnv("avx512", SimdLevel::Avx2, error) == SimdLevel::Avx2);
    CHECK(contains(error, "cannot run avx512"));
    CHECK(contains(error, "AVX-512"));
    CHECK(contains(error, "using avx2"));
}

TEST_CASE("simd dispatch: the best level follows the CPU query; the override falls back to it", "[simd]") {
#ifdef PS11_HAVE_AVX2
    const ps11::CpuFeatures& f = ps11::cpuFeatures();
    const bool avx2 = f.avx2Fma() && f.f16c;
#else
    const bool avx2 = false;
#endif
#ifdef PS11_HAVE_AVX512
    const bool avx512 = avx2 && f.avx512;
#else
    const bool avx512 = false;
#endif
    CHECK(ps11::simdLevelRuns(SimdLevel::Baseline));
    CHECK(ps11::simdLevelRuns(SimdLevel::Avx2) == avx2);
    CHECK(ps11::simdLevelRuns(SimdLevel::Avx512) == avx512);
    CHECK(ps11::bestSimdLevel() == (avx512 ? SimdLevel::Avx512 : avx2 ? SimdLevel::Avx2 : SimdLevel::Baseline));
    const std::vector<SimdLevel> levels = ps11::runnableSimdLevels();
    REQUIRE(!levels.empty());
    CHECK(levels.size() == size_t(1 + avx2 + avx512));
    CHECK(levels.front() == SimdLevel::Baseline);
    CHECK(levels.back() == ps11::bestSimdLevel());
    const SimdLevel avx2OrLess = avx2 ? SimdLevel::Avx2 : SimdLevel::Baseline;

    const SimdLevel before = ps11::simdLevel();
    {
        const ps11::ScopedSimdLevel outer(SimdLevel::Baseline);
        CHECK(outer.level() == SimdLevel::Baseline);
        CHECK(ps11::simdLevel() == SimdLevel::Baseline);
        {
            // Avx2 where the CPU runs it, else the best it runs (Baseline).
            const ps11::ScopedSimdLevel inner(SimdLevel::Avx2);
            CHECK(inner.level() == avx2OrLess);
            CHECK(ps11::simdLevel() == inner.level());
        }
        CHECK(ps11::simdLevel() == SimdLevel::Baseline);
    }
    CHECK(ps11::simdLevel() == before);
    CHECK(ps11::setSimdLevel(SimdLevel::Avx2) == avx2OrLess);
    CHECK(ps11::setSimdLevel(SimdLevel::Avx512) == ps11::bestSimdLevel());
    CHECK(ps11::setSimdLevel(SimdLevel::Baseline) == SimdLevel::Baseline);
    CHECK(ps11::simdLevel() == SimdLevel::Baseline);
    ps11::clearSimdLevel();
    CHECK(ps11::simdLevel() == before);
}

namespace {

// Runs a float-profile program over `count` pixels (one span) at the level in force; returns
// the output colours' bits and the killed flags.
std::vector<uint32_t> runFloat(const ps11::Executor& e, const std::vector<float> (&tc)[8][4],
                               const std::vector<float> (&col)[2][4], int count) {
    ps11::PixelInputs in;
    in.count = count;
    for (int v = 0; v < 2; ++v)
        for (int c = 0; c < 4; ++c) in.color[v][c] = col[v][c].data();
    for (int t = 0; t < 8; ++t)
        for (int c = 0; c < 4; ++c) in.texcoord[t][c] = tc[t][c].data();
    std::vector<float> color[4];
    std::vector<uint8_t> killed(size_t(count), 9);
    ps11::PixelOutputs out;
    for (int c = 0; c < 4; ++c) color[c].assign(size_t(count), -7.0f), out.color[c] = color[c].data();
    out.killed = killed.data();
    ps11::NullSampler sampler;
    e.run(in, sampler, out);
    std::vector<uint32_t> bits;
    for (int c = 0; c < 4; ++c)
        for (float f : color[c]) {
            uint32_t b;
            std::memcpy(&b, &f, 4);
            bits.push_back(b);
        }
    for (uint8_t k : killed) bits.push_back(k);
    return bits;
}

std::unique_ptr<ps11::Executor> makeFloat(const ps11::Program& program, ps11::Precision precision) {
    ps11::Diagnostics diags;
    ps11::ExecutorOptions opt;
    opt.precision = precision;
    std::unique_ptr<ps11::Executor> e = ps11::Executor::create(program, opt, diags);
    REQUIRE(e);
    return e;
}

}  // namespace

TEST_CASE("simd dispatch: float arithmetic gives the same bits at every level (float, ideal)", "[simd][executor]") {
    using namespace execrand;
    Gen g(0x51d0f10u);
    int valid = 0, generated = 0, compared = 0;
    int64_t bad = 0;
    while (valid < 300 && generated < 30000) {
        const int minor = 1 + generated++ % 4;
        const Prog p = g.program(minor);
        std::string err;
        const std::optional<ps11::Program> program = assemble(progText(p), err);
        if (!program) continue;
        ++valid;
        const int count = g.uni(1, ps11::kMaxSpan);
        std::vector<float> tc[8][4], col[2][4];
        for (auto& t : tc)
            for (auto& c : t) c.resize(size_t(count));
        for (auto& v : col)
            for (auto& c : v) c.resize(size_t(count));
        for (int i = 0; i < count; ++i) {
            const Inputs in = g.inputs();
            for (int t = 0; t < 8; ++t)
                for (int c = 0; c < 4; ++c) tc[t][c][size_t(i)] = in.tc[t][c];
            for (int v = 0; v < 2; ++v)
                for (int c = 0; c < 4; ++c) col[v][c][size_t(i)] = in.color[v][c];
        }
        const Inputs consts = g.inputs();
        for (ps11::Precision precision : {ps11::Precision::Float, ps11::Precision::Ideal}) {
            std::unique_ptr<ps11::Executor> e = makeFloat(*program, precision);
            for (int i = 0; i < 8; ++i) e->setConstant(i, consts.consts[i]);
            std::vector<uint32_t> first;
            testutil::forEachSimdLevel([&](SimdLevel level) {
                const std::vector<uint32_t> got = runFloat(*e, tc, col, count);
                if (level == SimdLevel::Baseline) {
                    first = got;
                    return;
                }
                ++compared;
                if (got != first && bad++ < 3) FAIL_CHECK(ps11::precisionName(precision) << "\n" << progText(p));
            });
        }
    }
    CHECK(valid >= 300);
    CHECK(bad == 0);
    // Both profiles at every level past Baseline.
    CHECK(compared == 2 * valid * int(ps11::runnableSimdLevels().size() - 1));
}

TEST_CASE("simd dispatch: float mad, lrp and dp3 round each product at every level (no FMA)", "[simd][executor]") {
    // a·b + c rounded twice, as written: an FMA would round once and differ for most operands.
    ps11::Diagnostics diags;
    const char* text =
        "ps_1_4\ntexcrd r0.xyz, t0\ntexcrd r1.xyz, t1\ntexcrd r2.xyz, t2\n"
        "mad r3.rgb, r0, r1, r2\nlrp r4.rgb, r0, r1, r2\ndp3 r5.rgb, r0, r1\n"
        "mov r0.r, r3.r\nmov r0.g, r4.g\nmov r0.b, r5.b\n";
    const std::optional<ps11::Program> program = ps11::parseAssembly(text, "fma.psh", {}, diags);
    REQUIRE(program);
    REQUIRE(ps11::validate(*program, diags));
    std::unique_ptr<ps11::Executor> e = makeFloat(*program, ps11::Precision::Ideal);
    const int count = ps11::kMaxSpan;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<float> tc[8][4], col[2][4];
    for (auto& t : tc)
        for (auto& c : t) c.assign(size_t(count), 0.0f);
    for (auto& v : col)
        for (auto& c : v) c.assign(size_t(count), 0.0f);
    for (int t = 0; t < 3; ++t)
        for (int c = 0; c < 3; ++c)
            for (float& f : tc[t][c]) f = u(rng);
    auto asFloat = [](uint32_t b) {
        float f;
        std::memcpy(&f, &b, 4);
        return f;
    };
    testutil::forEachSimdLevel([&](SimdLevel) {
        const std::vector<uint32_t> got = runFloat(*e, tc, col, count);
        int wrong = 0;
        for (int i = 0; i < count; ++i) {
            const size_t k = size_t(i);
            const float a0 = tc[0][0][k], b0 = tc[1][0][k], c0 = tc[2][0][k];
            const float a1 = tc[0][1][k], b1 = tc[1][1][k], c1 = tc[2][1][k];
            const float prod = a0 * b0;
            const float mad = prod + c0;
            const float diff = b1 - c1;
            const float scaled = a1 * diff;
            const float lrp = c1 + scaled;
            float dp = tc[0][0][k] * tc[1][0][k];
            const float p1 = tc[0][1][k] * tc[1][1][k];
            dp = dp + p1;
            const float p2 = tc[0][2][k] * tc[1][2][k];
            dp = dp + p2;
            wrong += asFloat(got[k]) != mad;
            wrong += asFloat(got[size_t(count) + k]) != lrp;
            wrong += asFloat(got[2 * size_t(count) + k]) != dp;
        }
        CHECK(wrong == 0);
    });
}

TEST_CASE("simd dispatch: every family has its tables, distinct per level where the build has Avx2", "[simd]") {
    using namespace ps11;
    const exec::FastKernels* fastB = exec::fastKernels(SimdLevel::Baseline);
    const exec::FastKernels* fastA = exec::fastKernels(SimdLevel::Avx2);
#ifdef PS11_HAVE_AVX2
    REQUIRE(fastB);
    REQUIRE(fastA);
    CHECK(std::string(fastB->name) == "fast-sse2");
    CHECK(std::string(fastA->name) == "fast-avx2");
    CHECK(&exec::floatArithKernels(SimdLevel::Baseline) != &exec::floatArithKernels(SimdLevel::Avx2));
    CHECK(&fastpath::samplerKernels(SimdLevel::Baseline) != &fastpath::samplerKernels(SimdLevel::Avx2));
    CHECK(emu::alignedKernels(SimdLevel::Avx2) != nullptr);
    CHECK(&emu::mergerKernels(SimdLevel::Baseline) != &emu::mergerKernels(SimdLevel::Avx2));
#else
    // No x86 kernels: the generic path runs every program; every other family has only Baseline.
    CHECK(fastB == nullptr);
    CHECK(fastA == nullptr);
    CHECK(&exec::floatArithKernels(SimdLevel::Baseline) == &exec::floatArithKernels(SimdLevel::Avx2));
    CHECK(emu::alignedKernels(SimdLevel::Avx2) == nullptr);
#endif
    // The aligned-pass path has no vector kernels at Baseline (every pixel on its own).
    CHECK(emu::alignedKernels(SimdLevel::Baseline) == nullptr);
    // Avx512: the generic path's arithmetic, the fx8 fast path and (in part) the aligned pass and
    // the output merger have their own tables; every other family runs its Avx2 one.
    CHECK(&fastpath::samplerKernels(SimdLevel::Avx512) == &fastpath::samplerKernels(SimdLevel::Avx2));
    // Some Avx512 tables are made on first use by code compiled for AVX-512 (ps11::madeTable): a
    // CPU without it gets the Avx2 tables (making them stopped a Zen 3 host on an illegal
    // instruction, 2026-12-02), so the distinct tables are looked for only where it runs.
#ifdef PS11_HAVE_AVX512
    if (!simdLevelRuns(SimdLevel::Avx512)) {
        CHECK(emu::alignedKernels(SimdLevel::Avx512) == emu::alignedKernels(SimdLevel::Avx2));
        CHECK(&emu::mergerKernels(SimdLevel::Avx512) == &emu::mergerKernels(SimdLevel::Avx2));
        CHECK(&emu::floatRowKernels(SimdLevel::Avx512) == &emu::floatRowKernels(SimdLevel::Avx2));
        return;
    }
    CHECK(&exec::fxArithKernels(SimdLevel::Avx512) != &exec::fxArithKernels(SimdLevel::Avx2));
    CHECK(&exec::floatArithKernels(SimdLevel::Avx512) != &exec::floatArithKernels(SimdLevel::Avx2));
    REQUIRE(exec::fastKernels(SimdLevel::Avx512));
    CHECK(std::string(exec::fastKernels(SimdLevel::Avx512)->name) == "fast-avx512");
    CHECK(exec::fastKernels(SimdLevel::Avx512)->lanes == 32);
    // The aligned pass's: its own vertical blends and deinterleave, the Avx2 level's other kernels.
    REQUIRE(emu::alignedKernels(SimdLevel::Avx512));
    CHECK(emu::alignedKernels(SimdLevel::Avx512) != emu::alignedKernels(SimdLevel::Avx2));
    CHECK(emu::alignedKernels(SimdLevel::Avx512)->vertical != emu::alignedKernels(SimdLevel::Avx2)->vertical);
    CHECK(emu::alignedKernels(SimdLevel::Avx512)->storeRow == emu::alignedKernels(SimdLevel::Avx2)->storeRow);
    // The merger's: its own float-to-8-bit words and ONE/ONE words, the Avx2 level's other kernels.
    const emu::MergerKernels& m512 = emu::mergerKernels(SimdLevel::Avx512);
    const emu::MergerKernels& m2 = emu::mergerKernels(SimdLevel::Avx2);
    CHECK(&m512 != &m2);
    CHECK(m512.unorm8Words != m2.unorm8Words);
    CHECK(m512.unorm8WordsRgba != m2.unorm8WordsRgba);
    CHECK(m512.addUnorm8Words != m2.addUnorm8Words);
    CHECK(m512.halves == m2.halves);
    // The float row path's: its own decode and row and column lerps, the Avx2 level's other kernels.
    const emu::FloatRowKernels& f512 = emu::floatRowKernels(SimdLevel::Avx512);
    const emu::FloatRowKernels& f2 = emu::floatRowKernels(SimdLevel::Avx2);
    CHECK(f512.decode != f2.decode);
    CHECK(f512.lerpRow != f2.lerpRow);
    CHECK(f512.lerpGather == f2.lerpGather);
#else
    CHECK(exec::fastKernels(SimdLevel::Avx512) == exec::fastKernels(SimdLevel::Avx2));
    CHECK(emu::alignedKernels(SimdLevel::Avx512) == emu::alignedKernels(SimdLevel::Avx2));
    CHECK(&emu::mergerKernels(SimdLevel::Avx512) == &emu::mergerKernels(SimdLevel::Avx2));
#endif
}

TEST_CASE("simd dispatch: the merger's half conversion gives the same halves at every level", "[simd][merger]") {
    // Every half pattern as a float, then floats between halves (ties, the overflow boundary,
    // subnormals), in spans whose lengths are not multiples of 8; NaNs stay NaNs.
    std::vector<float> values;
    for (uint32_t h = 0; h < 65536; ++h) values.push_back(emu::halfToFloat(uint16_t(h)));
    std::mt19937 rng(3);
    for (int i = 0; i < 65536; ++i) {
        uint32_t bits = rng();
        if (i % 3 == 0) bits = (bits & 0x80000000u) | (0x33000000u + (bits % 0x14800000u));
        if (i % 3 == 1) bits = (bits & 0xffffe000u) | 0x1000u;
        float f;
        std::memcpy(&f, &bits, 4);
        values.push_back(f);
    }
    const emu::MergerKernels& base = emu::mergerKernels(SimdLevel::Baseline);
    int64_t bad = 0;
    for (SimdLevel level : ps11::runnableSimdLevels()) {
        const emu::MergerKernels& k = emu::mergerKernels(level);
        for (size_t at = 0; at + 4 * 256 <= values.size(); at += 4 * 256) {
            const int count = 1 + int((at / 1024) % 256);
            const float* f[4] = {&values[at], &values[at + 256], &values[at + 512], &values[at + 768]};
            std::vector<uint16_t> want(size_t(4 * count)), got(size_t(4 * count));
            base.halves(f, count, want.data());
            k.halves(f, count, got.data());
            for (size_t j = 0; j < got.size(); ++j) {
                const bool nanWant = (want[j] & 0x7c00) == 0x7c00 && (want[j] & 0x3ff);
                const bool nanGot = (got[j] & 0x7c00) == 0x7c00 && (got[j] & 0x3ff);
                bad += nanWant ? !nanGot : got[j] != want[j];
            }
        }
        INFO("SIMD level " << ps11::simdLevelName(level));
        CHECK(bad == 0);
    }
}

namespace {

// Probes of the 8-bit rounding: every tie k + 1/2 over 255 and its float neighbours, the ends of
// [0, 1], values outside it, ±0, ±Inf and NaN, then random bits.
std::vector<float> unorm8Probes() {
    std::vector<float> values;
    for (int k = 0; k < 256; ++k) {
        const float tie = float((k + 0.5) / 255.0);
        values.insert(values.end(), {tie, std::nextafter(tie, 0.0f), std::nextafter(tie, 2.0f), float(k / 255.0)});
    }
    const float inf = std::numeric_limits<float>::infinity();
    values.insert(values.end(), {0.0f, -0.0f, 1.0f, std::nextafter(1.0f, 2.0f), -1e-30f, 7.5f, -3.0f, inf, -inf,
                                 std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::quiet_NaN()});
    std::mt19937 rng(11);
    for (int i = 0; i < 4096; ++i) {
        uint32_t bits = rng();
        float f;
        std::memcpy(&f, &bits, 4);
        values.push_back(i % 2 ? f : float(rng() % 100000) / 90000.0f);
    }
    return values;
}

// The A8R8G8B8 word of r g b a by ps11::unorm8OfFloat, ORed with `fill`.
uint32_t unorm8WordOf(float r, float g, float b, float a, uint32_t fill) {
    return (uint32_t(ps11::unorm8OfFloat(a)) << 24 | uint32_t(ps11::unorm8OfFloat(r)) << 16 |
            uint32_t(ps11::unorm8OfFloat(g)) << 8 | ps11::unorm8OfFloat(b)) |
           fill;
}

}  // namespace

TEST_CASE("simd dispatch: the merger's 8-bit words are ps11::unorm8OfFloat at every level", "[simd][merger]") {
    // Spans of every length 0..40 at every offset mod 8.
    const std::vector<float> values = unorm8Probes();
    int64_t bad = 0, checked = 0;
    for (SimdLevel level : ps11::runnableSimdLevels()) {
        const emu::MergerKernels& k = emu::mergerKernels(level);
        for (size_t at = 0; at + 4 * 48 <= values.size(); at += 37) {
            const int count = int(at % 41);
            const float* f[4] = {&values[at], &values[at + 48], &values[at + 96], &values[at + 144]};
            for (uint32_t fill : {0u, 0xff000000u}) {
                std::vector<uint32_t> got(size_t(count) + 1, 0xdeadbeefu);
                k.unorm8Words(f, count, fill, got.data());
                for (int i = 0; i < count; ++i) {
                    const uint32_t want = unorm8WordOf(f[0][i], f[1][i], f[2][i], f[3][i], fill);
                    bad += got[size_t(i)] != want;
                    ++checked;
                }
                bad += got[size_t(count)] != 0xdeadbeefu;  // nothing past the span
            }
        }
        INFO("SIMD level " << ps11::simdLevelName(level));
        CHECK(bad == 0);
    }
    CHECK(checked > 10000);
    // The rule itself (docs/precision.md "Outputs"): ties to even, clamped, NaN 0.
    CHECK(ps11::unorm8OfFloat(0.5) == 128);  // 127.5: the even neighbour
    CHECK(ps11::unorm8OfFloat(1.0) == 255);
    CHECK(ps11::unorm8OfFloat(std::numeric_limits<double>::quiet_NaN()) == 0);
    CHECK(ps11::unorm8OfFloat(-2.0) == 0);
    CHECK(ps11::unorm8OfFloat(2.0) == 255);
}

TEST_CASE("simd dispatch: ONE/ONE words into 8-bit targets are the bytes of sat(s) + byte / 255 at every level",
          "[simd][merger]") {
    // Every byte in every channel position, against probe sources (NaN, ±0, negatives, past 1,
    // ties of the 8-bit rounding), and sources mostly not above 0 (whole blocks of eight kept as
    // they are, others with one lane above); every length 0..40 at every offset; both fills.
    const std::vector<float> probes = unorm8Probes();
    const float* unit = ps11::Texture::unorm8Values();
    auto sat = [](float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; };
    auto want = [&](const float* const s[4], uint32_t d, int i, uint32_t fill) {
        return unorm8WordOf(sat(s[0][i]) + unit[(d >> 16) & 0xffu], sat(s[1][i]) + unit[(d >> 8) & 0xffu],
                            sat(s[2][i]) + unit[d & 0xffu], sat(s[3][i]) + unit[d >> 24], fill);
    };
    std::vector<float> dark(probes.size());
    const float notAbove[4] = {0.0f, -0.0f, -0.5f, std::numeric_limits<float>::quiet_NaN()};
    for (size_t i = 0; i < dark.size(); ++i) dark[i] = i % 53 == 7 ? probes[i] : notAbove[i % 4];
    int64_t bad = 0, checked = 0;
    for (SimdLevel level : ps11::runnableSimdLevels()) {
        const emu::MergerKernels& k = emu::mergerKernels(level);
        for (const std::vector<float>* values : {&probes, static_cast<const std::vector<float>*>(&dark)})
            for (size_t at = 0; at + 4 * 48 <= values->size(); at += 29) {
                const int count = int(at % 41);
                const float* s[4] = {&(*values)[at], &(*values)[at + 48], &(*values)[at + 96], &(*values)[at + 144]};
                std::vector<uint32_t> words(static_cast<size_t>(count));
                for (int i = 0; i < count; ++i) words[size_t(i)] = uint32_t(at * 2654435761u + uint64_t(i) * 40503u);
                for (uint32_t fill : {0u, 0xff000000u}) {
                    std::vector<uint32_t> got(size_t(count) + 1, 0xdeadbeefu);
                    k.addUnorm8Words(s, reinterpret_cast<const uint8_t*>(words.data()), count, fill, got.data());
                    for (int i = 0; i < count; ++i) {
                        bad += got[size_t(i)] != want(s, words[size_t(i)], i, fill);
                        ++checked;
                    }
                    bad += got[size_t(count)] != 0xdeadbeefu;  // nothing past the span
                }
            }
        // Every byte once in every channel of a 256-lane span, over sources of 0, −0 and 1/510
        // (half a step: the sums are ties or next to them).
        std::vector<uint32_t> words(256), got(256);
        for (float v : {0.0f, 1.0f / 510.0f, -0.0f}) {
            std::vector<float> lanes(256, v);
            const float* s[4] = {lanes.data(), lanes.data(), lanes.data(), lanes.data()};
            for (uint32_t b = 0; b < 256; ++b) words[b] = b * 0x01010101u ^ 0x00ff00ffu;
            k.addUnorm8Words(s, reinterpret_cast<const uint8_t*>(words.data()), 256, 0, got.data());
            for (uint32_t b = 0; b < 256; ++b) bad += got[b] != want(s, words[b], int(b), 0), ++checked;
        }
        INFO("SIMD level " << ps11::simdLevelName(level));
        CHECK(bad == 0);
    }
    CHECK(checked > 5000);
}

TEST_CASE("simd dispatch: the 8-bit words round every float next to a tie as ps11::unorm8OfFloat", "[simd][merger]") {
    // The floats within 96 ulps of each (k + 1/2) / 255, where a product v·255 rounded to float
    // lands on a tie that the exact product is not (a kernel must round the exact product), and
    // every 4099th float of [0, 1]; each level's words against the rule.
    std::vector<float> values;
    for (int k = 0; k < 255; ++k) {
        float v = float((k + 0.5) / 255.0);
        for (int s = 0; s < 96; ++s) v = std::nextafter(v, 0.0f);
        for (int s = 0; s < 192; ++s, v = std::nextafter(v, 2.0f)) values.push_back(v);
    }
    for (uint32_t bits = 0; bits <= 0x3f800000u; bits += 4099) {
        float v;
        std::memcpy(&v, &bits, 4);
        values.push_back(v);
    }
    values.resize((values.size() + 3) / 4 * 4, 0.5f);
    const size_t n = values.size() / 4;
    int64_t bad = 0;
    for (SimdLevel level : ps11::runnableSimdLevels()) {
        const emu::MergerKernels& k = emu::mergerKernels(level);
        const float* f[4] = {&values[0], &values[n], &values[2 * n], &values[3 * n]};
        std::vector<uint32_t> got(n), gotRgba(n);
        k.unorm8Words(f, int(n), 0, got.data());
        // The same values as interleaved pixels.
        k.unorm8WordsRgba(values.data(), int(n), 0, gotRgba.data());
        for (size_t i = 0; i < n; ++i) {
            bad += got[i] != unorm8WordOf(f[0][i], f[1][i], f[2][i], f[3][i], 0);
            const float* p = &values[4 * i];
            bad += gotRgba[i] != unorm8WordOf(p[0], p[1], p[2], p[3], 0);
        }
        INFO("SIMD level " << ps11::simdLevelName(level));
        CHECK(bad == 0);
    }
    CHECK(n > 50000);
}

TEST_CASE("simd dispatch: the float row path decodes every byte to the texture's value at every level",
          "[simd][aligned]") {
    // A row of 300 texels holding every byte in every channel (b g r a), decoded from every
    // offset 0..7 and to every length 0..300 - offset in steps: planar floats equal to
    // unorm8Values()[byte] bit for bit.
    const float* unit = ps11::Texture::unorm8Values();
    std::vector<uint8_t> row(300 * 4);
    for (size_t i = 0; i < row.size(); ++i) row[i] = uint8_t(i * 37 + i / 4);
    int64_t bad = 0, checked = 0;
    for (SimdLevel level : ps11::runnableSimdLevels()) {
        const emu::FloatRowKernels& k = emu::floatRowKernels(level);
        for (int offset = 0; offset < 8; ++offset)
            for (int n = 0; n + offset <= 300; n += 23) {
                const size_t stride = size_t(n) + 3;
                std::vector<float> out(4 * stride, -5.0f);
                k.decode(row.data() + 4 * offset, n, out.data(), stride);
                constexpr int kByte[4] = {2, 1, 0, 3};  // r g b a in b g r a
                for (int c = 0; c < 4; ++c) {
                    for (int i = 0; i < n; ++i) {
                        const float want = unit[row[size_t(4 * (offset + i) + kByte[c])]];
                        bad += std::memcmp(&out[size_t(c) * stride + size_t(i)], &want, 4) != 0;
                        ++checked;
                    }
                    bad += out[size_t(c) * stride + size_t(n)] != -5.0f;  // nothing past the row
                }
            }
        INFO("SIMD level " << ps11::simdLevelName(level));
        CHECK(bad == 0);
    }
    CHECK(checked > 50000);
}

TEST_CASE("simd dispatch: the float row path's lerps from 8-bit words are the decoded texels' lerps at every level",
          "[simd][aligned]") {
    // Columns of every kind the kernel tells apart: 2:1 and 4:1 reductions (i0 = base + s·j,
    // i1 = i0 + 1), magnifications within eight texels, scattered pairs, repeats; spans of 0..40
    // columns starting at every phase of those patterns, against (1 − f)·a + f·b of the texels'
    // values (unorm8Values), channel planes at a stride, nothing written past them.
    const float* unit = ps11::Texture::unorm8Values();
    std::mt19937 rng(5);
    std::vector<uint8_t> row(400 * 4);
    for (uint8_t& b : row) b = uint8_t(rng());
    const int len = 400;
    int64_t bad = 0, checked = 0;
    for (SimdLevel level : ps11::runnableSimdLevels()) {
        const emu::FloatRowKernels& k = emu::floatRowKernels(level);
        for (int round = 0; round < 400; ++round) {
            const int n = round % 41, kind = round % 5, start = int(rng() % 100);
            std::vector<int32_t> i0(static_cast<size_t>(n)), i1(static_cast<size_t>(n));
            std::vector<float> f(static_cast<size_t>(n));
            for (int j = 0; j < n; ++j) {
                const int s = kind == 0 ? 2 : kind == 1 ? 4 : 0;
                i0[size_t(j)] = s ? start + s * j : kind == 2 ? start + j / 3 : int(rng() % (len - 1));
                i1[size_t(j)] = kind == 4 && j % 7 == 3 ? int(rng() % len) : i0[size_t(j)] + 1;
                f[size_t(j)] = float(rng() % 257) / 256.0f;
            }
            if (n > 9 && kind < 3 && round % 3 == 0)
                i0[size_t(n / 2)] += 1, i1[size_t(n / 2)] += 1;  // one column off the pattern
            const size_t stride = size_t(n) + 5;
            std::vector<float> out(4 * stride, -3.0f);
            k.lerpWords(row.data(), len, i0.data(), i1.data(), f.data(), n, out.data(), stride);
            constexpr int kByte[4] = {2, 1, 0, 3};  // r g b a in b g r a
            for (int c = 0; c < 4; ++c) {
                for (int j = 0; j < n; ++j) {
                    const float a = unit[row[size_t(4 * i0[size_t(j)] + kByte[c])]];
                    const float b = unit[row[size_t(4 * i1[size_t(j)] + kByte[c])]];
                    const float fj = f[size_t(j)];
                    const float want = (1.0f - fj) * a + fj * b;
                    bad += std::memcmp(&out[size_t(c) * stride + size_t(j)], &want, 4) != 0;
                    ++checked;
                }
                for (size_t j = size_t(n); j < stride; ++j) bad += out[size_t(c) * stride + j] != -3.0f;
            }
        }
        INFO("SIMD level " << ps11::simdLevelName(level));
        CHECK(bad == 0);
    }
    CHECK(checked > 20000);
}

TEST_CASE("simd dispatch: the float row path's lerps from float texels are the reference lerps at every level",
          "[simd][aligned]") {
    // Rows of float r g b a texels (finite values, and rows with an infinity or a NaN), columns
    // of random pairs and reductions, spans of 0..40: where a level's kernel reports success its
    // planes hold (1 − f)·a + f·b bit for bit; it may report failure only when a result is NaN.
    std::mt19937 rng(6);
    std::uniform_real_distribution<float> value(-4.0f, 4.0f);
    int64_t bad = 0, checked = 0, refused = 0;
    for (SimdLevel level : ps11::runnableSimdLevels()) {
        const emu::FloatRowKernels& k = emu::floatRowKernels(level);
        for (int round = 0; round < 400; ++round) {
            const int len = 200, n = round % 41;
            std::vector<float> row(size_t(len) * 4);
            for (float& v : row) v = value(rng);
            if (round % 4 == 1) row[rng() % row.size()] = std::numeric_limits<float>::infinity();
            if (round % 4 == 2) row[rng() % row.size()] = std::numeric_limits<float>::quiet_NaN();
            std::vector<int32_t> i0(static_cast<size_t>(n)), i1(static_cast<size_t>(n));
            std::vector<float> f(static_cast<size_t>(n));
            const int start = int(rng() % 20);
            for (int j = 0; j < n; ++j) {
                i0[size_t(j)] = round % 3 == 0 ? start + 4 * j : int(rng() % (len - 1));
                i1[size_t(j)] = round % 5 == 0 ? int(rng() % len) : i0[size_t(j)] + 1;
                f[size_t(j)] = round % 7 == 0 ? float(j % 2) : float(rng() % 257) / 256.0f;
            }
            const size_t stride = size_t(n) + 3;
            std::vector<float> out(4 * stride, -3.0f);
            const bool done = k.lerpValues(row.data(), len, i0.data(), i1.data(), f.data(), n, out.data(), stride);
            bool anyNan = false;
            for (int c = 0; c < 4; ++c)
                for (int j = 0; j < n; ++j) {
                    const float a = row[4 * size_t(i0[size_t(j)]) + size_t(c)],
                                b = row[4 * size_t(i1[size_t(j)]) + size_t(c)];
                    const float fj = f[size_t(j)];
                    const float want = (1.0f - fj) * a + fj * b;
                    anyNan |= want != want;
                    if (!done) continue;
                    const float got = out[size_t(c) * stride + size_t(j)];
                    bad += std::memcmp(&got, &want, 4) != 0 && !(got != got && want != want);
                    ++checked;
                }
            if (!done) {
                ++refused;
                bad += !anyNan;
            } else {
                for (int c = 0; c < 4; ++c)
                    for (size_t j = size_t(n); j < stride; ++j) bad += out[size_t(c) * stride + j] != -3.0f;
            }
        }
        INFO("SIMD level " << ps11::simdLevelName(level));
        CHECK(bad == 0);
    }
    CHECK(checked > 20000);
    if (ps11::runnableSimdLevels().size() > 1) CHECK(refused > 0);  // the rows with a NaN or an infinity
}

TEST_CASE("simd dispatch: the 8-bit words of interleaved float pixels are ps11::unorm8OfFloat at every level",
          "[simd][merger]") {
    // The A32B32G32R32F rows a StretchRect converts, as r g b a quadruples of the probes; every
    // length 0..40 at every offset.
    const std::vector<float> values = unorm8Probes();
    int64_t bad = 0, checked = 0;
    for (SimdLevel level : ps11::runnableSimdLevels()) {
        const emu::MergerKernels& k = emu::mergerKernels(level);
        for (size_t at = 0; at + 4 * 41 <= values.size(); at += 13) {
            const int count = int(at % 41);
            const float* rgba = &values[at];
            for (uint32_t fill : {0u, 0xff000000u}) {
                std::vector<uint32_t> got(size_t(count) + 1, 0xdeadbeefu);
                k.unorm8WordsRgba(rgba, count, fill, got.data());
                for (int i = 0; i < count; ++i) {
                    const float* p = rgba + 4 * i;
                    bad += got[size_t(i)] != unorm8WordOf(p[0], p[1], p[2], p[3], fill);
                    ++checked;
                }
                bad += got[size_t(count)] != 0xdeadbeefu;  // nothing past the span
            }
        }
        INFO("SIMD level " << ps11::simdLevelName(level));
        CHECK(bad == 0);
    }
    CHECK(checked > 10000);
}

TEST_CASE("simd dispatch: mergePixels stores the same A16B16G16R16F bytes at every level", "[simd][merger]") {
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(-70000.0f, 70000.0f), small(-1.0f, 1.0f);
    const int count = 200;  // not a multiple of 8
    std::vector<int32_t> x(count), y(count);
    std::vector<uint8_t> live(count);
    std::vector<float> color[4];
    for (int i = 0; i < count; ++i) x[size_t(i)] = i % 16, y[size_t(i)] = i / 16, live[size_t(i)] = i % 7 != 3;
    for (int c = 0; c < 4; ++c)
        for (int i = 0; i < count; ++i) color[c].push_back(i % 2 ? u(rng) : small(rng));
    emu::MergeInputs in;
    in.count = count;
    in.x = x.data(), in.y = y.data(), in.live = live.data();
    for (int c = 0; c < 4; ++c) in.color[c] = color[c].data();
    for (uint32_t mask : {0xfu, 0x5u, 0x8u}) {
        std::vector<uint8_t> first;
        testutil::forEachSimdLevel([&](SimdLevel level) {
            emu::Image img;
            img.format = emu::formatInfo(emu::D3DFMT_A16B16G16R16F);
            REQUIRE(img.format);
            img.width = 16, img.height = 16;
            img.rowPitch = emu::rowPitchOf(*img.format, 16);
            img.slicePitch = uint64_t(img.rowPitch) * 16;
            img.bytes.assign(size_t(img.slicePitch), 0x5a);
            emu::MergeState st;
            st.precision = ps11::Precision::Float;
            st.colorWrite = mask;
            emu::MergeStats stats;
            emu::mergePixels(st, in, emu::MergeTarget{&img, nullptr}, &stats);
            CHECK(stats.written == uint64_t(count - (count + 3) / 7));
            const std::vector<uint8_t> bytes(img.bytes.begin(), img.bytes.end());
            if (level == SimdLevel::Baseline)
                first = bytes;
            else
                CHECK(bytes == first);
        });
    }
}
