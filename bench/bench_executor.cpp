// Benchmarks of the executor (Google Benchmark; never run by ctest): ns per pixel and ns per
// pixel per executed instruction, for each precision profile, on typical ps_1_1 programs over
// spans of kMaxSpan pixels. Textured programs run once with a TextureSampler over a 256×256
// A8R8G8B8 texture (bilinear) and once with the NullSampler, which separates the executor's
// own cost from the cost of sampling. How to run: bench/README.md.
#include <benchmark/benchmark.h>

#include "bench/bench_shaders.h"

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <ctime>
#include <string>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/diagnostics.h"
#include "ps11/executor.h"
#include "ps11/sampler.h"
#include "ps11/simd_dispatch.h"
#include "ps11/testfile.h"
#include "ps11/testfile_textures.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"
#include "ps11/validator.h"

namespace {

using bench::kBlur4;

using namespace ps11;

struct BenchProgram {
    const char* name;
    const char* text;
    bool textured;
};

// Bright pass: what exceeds the threshold c0, boosted and tinted.
constexpr const char* kBright =
    "ps_1_1\n"
    "tex t0\n"
    "sub_sat r0, t0, c0\n"
    "mul_x4 r0, r0, r0\n"
    "mul r0, r0, c1\n";

// Composite: scene t0 plus bloom t1 ("screen" t0 + (1 - t0)·bloom), blended by c0.a.
constexpr const char* kComposite =
    "ps_1_1\n"
    "tex t0\n"
    "tex t1\n"
    "mul r1, t1, c1\n"
    "mad r1, 1-t0, r1, t0\n"
    "lrp r0, c0.a, r1, t0\n";

// Pure arithmetic: eight dependent instructions on v0, v1 and constants.
constexpr const char* kArith =
    "ps_1_1\n"
    "mul r0, v0, c0\n"
    "mad r0, v1, c1, r0\n"
    "add r1, r0, c2\n"
    "mul_x2 r1, r1, v0\n"
    "sub r0, r1, v1\n"
    "mad_sat r0, r0, c3, c2\n"
    "dp3 r1, r0_bx2, v1_bx2\n"
    "lrp r0, r1, r0, v0\n";

const BenchProgram kPrograms[] = {
    {"blur4", kBlur4, true},
    {"bright", kBright, true},
    {"composite", kComposite, true},
    {"arith8", kArith, false},
};

const Precision kProfiles[] = {Precision::Fx8, Precision::Fx12, Precision::Float, Precision::Ideal};

constexpr int kTexSize = 256;

// Deterministic pseudo-random numbers (no <random> state differences between runs).
uint32_t hash(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

// A 256×256 A8R8G8B8 texture with smooth gradients and some noise (bilinear filtering
// then works on varied texels).
std::shared_ptr<const Texture> makeTexture() {
    TextureDesc desc;
    desc.width = desc.height = kTexSize;
    TextureLevel level;
    level.width = level.height = kTexSize;
    level.texels.resize(size_t(kTexSize) * kTexSize);
    for (int y = 0; y < kTexSize; ++y)
        for (int x = 0; x < kTexSize; ++x) {
            uint32_t n = hash(uint32_t(y * kTexSize + x)) & 0x3f;
            uint32_t r = (uint32_t(x) + n) & 0xff, g = (uint32_t(y) + n) & 0xff, b = (uint32_t(x ^ y)) & 0xff;
            level.texels[size_t(y) * kTexSize + x].bits = 0xff000000u | r << 16 | g << 8 | b;
        }
    desc.data.push_back(std::move(level));
    std::string error;
    std::optional<Texture> texture = textureFromDesc(desc, SignedDecode::Snorm, error);
    if (!texture) {
        std::fprintf(stderr, "bench: cannot build the texture: %s\n", error.c_str());
        return nullptr;
    }
    return std::make_shared<const Texture>(std::move(*texture));
}

std::unique_ptr<Sampler> makeSampler(bool textured) {
    if (!textured) return std::make_unique<NullSampler>();
    static std::shared_ptr<const Texture> texture = makeTexture();
    auto sampler = std::make_unique<TextureSampler>();
    SamplerDesc desc;
    desc.minFilter.value = desc.magFilter.value = Filter::Linear;
    desc.addressU.value = desc.addressV.value = desc.addressW.value = TextureAddress::Clamp;
    for (int stage = 0; stage < 4; ++stage) {
        sampler->bind(stage, texture);
        sampler->setSamplerState(stage, samplerStateFromDesc(desc));
    }
    return sampler;
}

// Interpolants of a few spans of pixels in rows of the texture: four taps half a texel apart
// (the blur's footprint), v0/v1 varied colours.
struct SpanInputs {
    static constexpr int kRows = 16;
    std::vector<float> data;
    std::array<PixelInputs, kRows> inputs;
    SpanInputs() {
        const int n = kMaxSpan;
        // Per row: v0 rgba, v1 rgba, TC0..3 u v w q = 8 + 16 arrays of n floats.
        data.assign(size_t(kRows) * 24 * n, 0.0f);
        const float offsets[4][2] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {-0.5f, 0.5f}, {0.5f, 0.5f}};
        for (int row = 0; row < kRows; ++row) {
            float* base = data.data() + size_t(row) * 24 * n;
            PixelInputs& in = inputs[row];
            in.count = n;
            in.quads = false;
            for (int r = 0; r < 2; ++r)
                for (int c = 0; c < 4; ++c) {
                    float* p = base + size_t(r * 4 + c) * n;
                    for (int i = 0; i < n; ++i) p[i] = float(hash(uint32_t(row * 7919 + i * 31 + r * 4 + c)) & 0xff) / 255.0f;
                    in.color[r][c] = p;
                }
            const float y = float(row * (kTexSize / kRows)) + 0.5f;
            for (int t = 0; t < 4; ++t) {
                float* u = base + size_t(8 + t * 4 + 0) * n;
                float* v = base + size_t(8 + t * 4 + 1) * n;
                for (int i = 0; i < n; ++i) {
                    u[i] = (float(i) + 0.5f + offsets[t][0]) / kTexSize;
                    v[i] = (y + offsets[t][1]) / kTexSize;
                }
                in.texcoord[t][0] = u;
                in.texcoord[t][1] = v;
                in.texcoord[t][2] = base + size_t(8 + t * 4 + 2) * n;  // w = 0
                in.texcoord[t][3] = base + size_t(8 + t * 4 + 3) * n;  // q = 0 (not projected)
            }
        }
    }
};

// CPU time of the calling thread in ns.
double threadCpuNs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e9 + double(ts.tv_nsec);
}

std::unique_ptr<Executor> makeExecutor(const char* text, Precision precision, ExecPath path) {
    Diagnostics diags;
    std::optional<Program> program = parseAssembly(text, "<bench>", AssembleOptions{}, diags);
    if (program) validate(*program, diags);
    std::unique_ptr<Executor> executor;
    if (program && !diags.hasErrors()) {
        ExecutorOptions options;
        options.precision = precision;
        options.path = path;
        executor = Executor::create(*program, options, diags);
    }
    if (!executor) {
        std::fprintf(stderr, "bench: cannot prepare the program:\n%s%s", text, diags.formatAll().c_str());
        return nullptr;
    }
    executor->setConstant(0, {0.25f, 0.25f, 0.25f, 0.6f});
    executor->setConstant(1, {0.9f, 0.8f, 0.7f, 1.0f});
    executor->setConstant(2, {0.1f, 0.2f, 0.3f, 0.4f});
    executor->setConstant(3, {0.5f, 0.75f, 0.25f, 1.0f});
    return executor;
}

// Outputs of one span.
struct SpanOutputs {
    std::array<std::vector<float>, 4> color;
    std::array<std::vector<int32_t>, 4> grid;
    std::vector<uint8_t> killed;
    PixelOutputs outputs;
    explicit SpanOutputs(Precision precision) {
        for (int c = 0; c < 4; ++c) {
            color[c].assign(kMaxSpan, 0.0f);
            grid[c].assign(kMaxSpan, 0);
            outputs.color[c] = color[c].data();
            if (isFixedPoint(precision)) outputs.grid[c] = grid[c].data();
        }
        killed.assign(kMaxSpan, 0);
        outputs.killed = killed.data();
    }
};

// Runs every row once through the executor and returns the thread CPU time in ns.
double timeRows(const Executor& executor, Sampler& sampler, const SpanInputs& spans, SpanOutputs& out) {
    const double start = threadCpuNs();
    for (const PixelInputs& in : spans.inputs) {
        executor.run(in, sampler, out.outputs);
        benchmark::DoNotOptimize(out.color[0].data());
        benchmark::ClobberMemory();
    }
    return threadCpuNs() - start;
}

// One benchmark per program × profile × sampler. Each iteration runs the 16 rows with the default
// path (Auto: the fast path where it applies) and, where the fast path applies, the same rows with
// the generic path and with the default path at the Baseline SIMD level (ps11::ScopedSimdLevel:
// what a CPU without AVX2 runs, sampler included) when the level in force is above it,
// alternating the order (A B C, C B A, …) so drift of the shared VM hits all alike.
// Thread CPU time, like the CPU column: on a shared VM wall time also counts other tenants.
void runProgram(benchmark::State& state, const BenchProgram& prog, Precision precision, bool textured) {
    std::unique_ptr<Executor> fast = makeExecutor(prog.text, precision, ExecPath::Auto);
    std::unique_ptr<Executor> generic = makeExecutor(prog.text, precision, ExecPath::Generic);
    if (!fast || !generic) {
        state.SkipWithError("cannot prepare the program");
        return;
    }
    const bool compare = std::string(fast->pathName()) != "generic";
    const bool compareBaseline = compare && simdLevel() != SimdLevel::Baseline;
    std::unique_ptr<Sampler> sampler = makeSampler(textured);
    static const SpanInputs spans;
    SpanOutputs out(precision);

    // Instructions per pixel, as the executor counts them.
    ExecutorStats stats;
    fast->run(spans.inputs[0], *sampler, out.outputs, &stats);
    const double perPixel = stats.pixels ? double(stats.instructions) / double(stats.pixels) : 0.0;

    auto timeBaseline = [&] {
        const ScopedSimdLevel baseline(SimdLevel::Baseline);
        return timeRows(*fast, *sampler, spans, out);
    };
    double tFast = 0, tGeneric = 0, tBaseline = 0;
    bool fastFirst = true;
    for (auto _ : state) {
        if (compare && !fastFirst) tGeneric += timeRows(*generic, *sampler, spans, out);
        if (compareBaseline && !fastFirst) tBaseline += timeBaseline();
        tFast += timeRows(*fast, *sampler, spans, out);
        if (compareBaseline && fastFirst) tBaseline += timeBaseline();
        if (compare && fastFirst) tGeneric += timeRows(*generic, *sampler, spans, out);
        fastFirst = !fastFirst;
    }
    const double pixels = double(state.iterations()) * SpanInputs::kRows * kMaxSpan;
    state.counters["ns/pixel"] = tFast / pixels;
    if (perPixel > 0) state.counters["ns/pixel/instr"] = tFast / (pixels * perPixel);
    state.counters["instr/pixel"] = perPixel;
    if (compare) {
        state.counters["generic_ns/pixel"] = tGeneric / pixels;
        if (perPixel > 0) state.counters["generic_ns/pixel/instr"] = tGeneric / (pixels * perPixel);
        state.counters["speedup"] = tFast > 0 ? tGeneric / tFast : 0.0;
    }
    if (compareBaseline) state.counters["baseline_ns/pixel"] = tBaseline / pixels;
    state.SetItemsProcessed(int64_t(pixels));
    state.SetLabel(fast->pathName());
}

// Registers program × profile (× sampler for textured programs).
int registerAll() {
    for (const BenchProgram& prog : kPrograms)
        for (Precision p : kProfiles)
            for (bool textured : {true, false}) {
                if (textured && !prog.textured) continue;
                std::string name = std::string(prog.name) + "/" + precisionName(p);
                if (prog.textured) name += textured ? "/bilinear" : "/nullsampler";
                benchmark::RegisterBenchmark(name.c_str(), [&prog, p, textured](benchmark::State& s) {
                    runProgram(s, prog, p, textured);
                });
            }
    return 0;
}
[[maybe_unused]] const int kRegistered = registerAll();

}  // namespace

BENCHMARK_MAIN();
