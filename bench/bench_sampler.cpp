// Benchmarks of the software sampler (Google Benchmark; never run by ctest): ns per lookup of
// the fast Unorm8 kernels against the reference path of TextureSampler, and the cost of handing
// a 1080p A8R8G8B8 texture to the sampler through the old .ps11test model (textureFromDesc, ps11/testfile_textures.h)
// against Texture::fromLevels. A and B run interleaved inside every iteration (A B A B ...), each
// timed on its own, so the reported ratio is taken under the same machine load; read the medians
// of repetitions. Times are this thread's CPU time. How to run: bench/README.md.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "ps11/testfile.h"
#include "ps11/testfile_textures.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"
#include "ps11/simd_dispatch.h"

namespace {

using namespace ps11;

// This thread's CPU time in ns: the machine is shared, so wall time also counts other agents.
struct Clock {
    static int64_t now() {
        timespec ts;
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
    }
};

constexpr uint32_t kW = 1920, kH = 1080;

// The bytes of a 1080p A8R8G8B8 level in D3D's layout (pitch = width * 4), random content.
const std::vector<uint8_t>& imageBytes() {
    static const std::vector<uint8_t> bytes = [] {
        std::vector<uint8_t> b(size_t(kW) * kH * 4);
        std::mt19937 rng(1);
        for (size_t i = 0; i < b.size(); i += 4) {
            const uint32_t w = rng();
            std::memcpy(&b[i], &w, 4);
        }
        return b;
    }();
    return bytes;
}

std::shared_ptr<const Texture> texture1080p() {
    static const std::shared_ptr<const Texture> t = [] {
        TextureLevelBytes l{kW, kH, 1, imageBytes().data(), kW * 4, size_t(kW) * 4 * kH};
        std::string error;
        std::optional<Texture> tex = Texture::fromLevels(TexFormat::A8R8G8B8, false, &l, 1, SignedDecode::Snorm, error);
        return std::make_shared<const Texture>(std::move(*tex));
    }();
    return t;
}

enum class Pattern { HalfTexelTaps, HalfTexelQuads, OneToOne, Random, Downsample2x };

// Coordinates of `rows` screen rows (spans of kMaxSpan lanes): the screen-aligned patterns of
// full-screen passes, or uniformly random positions in [0, 1).
struct Coords {
    std::vector<float> u, v;
};

Coords makeCoords(Pattern p, int rows) {
    Coords c;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int r = 0; r < rows; ++r) {
        const int y = int(uint32_t(r) * 67u % kH);  // rows spread over the texture
        for (uint32_t x = 0; x < kW; ++x) {
            float u = 0, v = 0;
            if (p == Pattern::HalfTexelQuads) {
                // 2x2 quads as the rasteriser sends them (TL TR BL BR): lane x of the row is pixel
                // (2 * (x / 4) + x % 2, y + (x / 2) % 2) of a two-row band.
                const uint32_t px = 2 * (x / 4) % kW + x % 2, py = (uint32_t(y) + (x / 2) % 2) % kH;
                c.u.push_back((float(px) + 1.0f) / float(kW)), c.v.push_back((float(py) + 1.0f) / float(kH));
                continue;
            }
            switch (p) {
                case Pattern::HalfTexelTaps:  // a blur tap half a texel right and down of the centre
                    u = (float(x) + 1.0f) / float(kW), v = (float(y) + 1.0f) / float(kH);
                    break;
                case Pattern::OneToOne:  // texel centres
                    u = (float(x) + 0.5f) / float(kW), v = (float(y) + 0.5f) / float(kH);
                    break;
                case Pattern::Downsample2x:  // 2:1 reduction: the corner shared by four texels
                    u = float(2 * (x % (kW / 2)) + 1) / float(kW), v = float(2 * (y % (kH / 2)) + 1) / float(kH);
                    break;
                case Pattern::Random:
                    u = unit(rng), v = unit(rng);
                    break;
                case Pattern::HalfTexelQuads:  // handled above
                    break;
            }
            c.u.push_back(u), c.v.push_back(v);
        }
    }
    return c;
}

// Samples every span of `c` once; returns the elapsed nanoseconds.
double pass(TextureSampler& s, const Coords& c, std::array<std::vector<int32_t>, 4>& out, bool quads) {
    SampleRequest req;
    req.quads = quads;
    req.precision = Precision::Fx8;
    SampleResult r;
    const auto t0 = Clock::now();
    for (size_t i = 0; i < c.u.size(); i += kMaxSpan) {
        req.count = int(std::min<size_t>(kMaxSpan, c.u.size() - i));
        req.u = c.u.data() + i, req.v = c.v.data() + i;
        for (int k = 0; k < 4; ++k) r.grid[k] = out[size_t(k)].data();
        s.sample(req, r);
        benchmark::DoNotOptimize(out[0][0]);
    }
    return double(Clock::now() - t0);
}

// fast vs reference on one pattern, interleaved; counters are ns per lookup and their ratio.
void BM_Lookup(benchmark::State& state, Pattern pattern, Filter filter, TextureAddress mode, bool baseline) {
    const Coords c = makeCoords(pattern, 8);
    TextureSampler fast(true), ref(false);
    SamplerState st;
    st.minFilter = st.magFilter = filter;
    st.addressU = st.addressV = mode;
    for (TextureSampler* s : {&fast, &ref}) {
        s->bind(0, texture1080p());
        s->setSamplerState(0, st);
    }
    std::array<std::vector<int32_t>, 4> out;
    for (auto& o : out) o.assign(kMaxSpan, 0);
    double fastNs = 0, refNs = 0;
    std::optional<ScopedSimdLevel> level;
    if (baseline) level.emplace(SimdLevel::Baseline);
    for (auto _ : state) {
        fastNs += pass(fast, c, out, pattern == Pattern::HalfTexelQuads);
        refNs += pass(ref, c, out, pattern == Pattern::HalfTexelQuads);
    }
    level.reset();
    const double lookups = double(c.u.size()) * double(state.iterations());
    state.counters["fast_ns"] = fastNs / lookups;
    state.counters["ref_ns"] = refNs / lookups;
    state.counters["ref/fast"] = refNs / fastNs;
    state.counters["fast_1080p_ms"] = fastNs / lookups * kW * kH * 1e-6;
}

// The old hand-over: one ps11::Texel per texel in a TextureDesc, then textureFromDesc (what
// emu's makeSampledTexture did before Texture::fromLevels).
std::optional<Texture> handOverOld(const std::vector<uint8_t>& bytes) {
    TextureDesc desc;
    desc.format = {TexFormat::A8R8G8B8, 1};
    desc.width = kW, desc.height = kH, desc.depth = 0;
    desc.levels = {1, 1};
    TextureLevel l;
    l.level = 0, l.width = kW, l.height = kH, l.depth = 1;
    l.texels.resize(size_t(kW) * kH);
    for (size_t i = 0; i < l.texels.size(); ++i) {
        const uint8_t* p = bytes.data() + i * 4;
        l.texels[i].bits = uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
    }
    desc.data.push_back(std::move(l));
    std::string error;
    return textureFromDesc(desc, SignedDecode::Snorm, error);
}

// Runs `a` then `b` in every iteration (A B A B ...), each timed on its own: their mean ms.
template <class A, class B>
std::pair<double, double> interleavedMs(benchmark::State& state, A&& a, B&& b) {
    double aNs = 0, bNs = 0;
    for (auto _ : state) {
        const auto t0 = Clock::now();
        a();
        const auto t1 = Clock::now();
        b();
        const auto t2 = Clock::now();
        aNs += double(t1 - t0);
        bNs += double(t2 - t1);
    }
    const double n = double(state.iterations());
    return {aNs / n * 1e-6, bNs / n * 1e-6};
}

void BM_HandOver1080p(benchmark::State& state) {
    const std::vector<uint8_t>& bytes = imageBytes();
    const TextureLevelBytes l{kW, kH, 1, bytes.data(), kW * 4, size_t(kW) * 4 * kH};
    std::string error;
    const auto [oldMs, newMs] = interleavedMs(
        state, [&] { benchmark::DoNotOptimize(handOverOld(bytes)); },
        [&] {
            benchmark::DoNotOptimize(
                Texture::fromLevels(TexFormat::A8R8G8B8, false, &l, 1, SignedDecode::Snorm, error));
        });
    state.counters["old_ms"] = oldMs;
    state.counters["new_ms"] = newMs;
    state.counters["old/new"] = oldMs / newMs;
}

// A 1080p float level handed over decoded into a copy (no owner: what the device's first read of a
// freshly drawn A16B16G16R16F or R32F target did before those were read in place) and read in
// place (an owner given), interleaved.
void BM_HandOverFloat1080p(benchmark::State& state, TexFormat format) {
    const uint32_t bpt = bytesPerTexel(format);
    auto bytes = std::shared_ptr<uint8_t[]>(new uint8_t[size_t(kW) * kH * bpt]);
    for (size_t i = 0; i < size_t(kW) * kH * bpt; i += 2) {  // halves (or float halves) near 0.3
        bytes[i] = uint8_t(i * 7);
        bytes[i + 1] = 0x34;
    }
    const TextureLevelBytes l{kW, kH, 1, bytes.get(), size_t(kW) * bpt, size_t(kW) * bpt * kH};
    std::string error;
    const auto [copyMs, inPlaceMs] = interleavedMs(
        state, [&] { benchmark::DoNotOptimize(Texture::fromLevels(format, false, &l, 1, SignedDecode::Snorm, error)); },
        [&] {
            benchmark::DoNotOptimize(Texture::fromLevels(format, false, &l, 1, SignedDecode::Snorm, error, bytes));
        });
    state.counters["copy_ms"] = copyMs;
    state.counters["in_place_ms"] = inPlaceMs;
}

}  // namespace

BENCHMARK_CAPTURE(BM_HandOverFloat1080p, a16b16g16r16f, TexFormat::A16B16G16R16F)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_HandOverFloat1080p, r32f, TexFormat::R32F)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, bilinear_halftexel_clamp, Pattern::HalfTexelTaps, Filter::Linear, TextureAddress::Clamp,
                  false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, bilinear_halftexel_wrap, Pattern::HalfTexelTaps, Filter::Linear, TextureAddress::Wrap,
                  false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, bilinear_halftexel_quads_clamp, Pattern::HalfTexelQuads, Filter::Linear,
                  TextureAddress::Clamp, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, bilinear_halftexel_clamp_baseline, Pattern::HalfTexelTaps, Filter::Linear,
                  TextureAddress::Clamp, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, bilinear_downsample2x_clamp, Pattern::Downsample2x, Filter::Linear, TextureAddress::Clamp,
                  false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, bilinear_random_wrap, Pattern::Random, Filter::Linear, TextureAddress::Wrap, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, bilinear_random_mirror, Pattern::Random, Filter::Linear, TextureAddress::Mirror, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, point_onetoone_clamp, Pattern::OneToOne, Filter::Point, TextureAddress::Clamp, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Lookup, point_random_border, Pattern::Random, Filter::Point, TextureAddress::Border, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_HandOver1080p)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
