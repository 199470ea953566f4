// The output merger alone (emu::mergePixels): ns per pixel over a 256x256 target in spans of
// 256 pixels (one row per call, as a rasteriser hands rows over, or as a row path's run: *_row),
// per configuration.
#include <benchmark/benchmark.h>

#include <cstring>
#include <vector>

#include "emu/format.h"
#include "emu/output_merger.h"
#include "emu/resources.h"

using namespace emu;
using ps11::Precision;

namespace {

constexpr int kSide = 256;

Image makeImage(D3DFORMAT f) {
    Image img;
    img.format = formatInfo(f);
    img.width = img.height = kSide;
    img.rowPitch = rowPitchOf(*img.format, kSide);
    img.slicePitch = uint64_t(img.rowPitch) * kSide;
    img.bytes.assign(size_t(img.slicePitch), 0x40);
    return img;
}

struct Inputs {
    std::vector<int32_t> x, y[kSide];
    std::vector<int32_t> grid[4];
    std::vector<float> color[4], fog, z;
    Inputs() : x(kSide), fog(kSide), z(kSide) {
        for (int i = 0; i < kSide; ++i) x[size_t(i)] = i;
        for (int r = 0; r < kSide; ++r) y[r].assign(kSide, r);
        for (int c = 0; c < 4; ++c) {
            grid[c].resize(kSide), color[c].resize(kSide);
            for (int i = 0; i < kSide; ++i) {
                grid[c][size_t(i)] = (i * 37 + c * 91) % 256;
                color[c][size_t(i)] = float(grid[c][size_t(i)]) / 255.0f;
            }
        }
        for (int i = 0; i < kSide; ++i) fog[size_t(i)] = float(i) / 255.0f, z[size_t(i)] = float(i % 100) / 100.0f;
    }
};

// `row`: each span is a row path's run (MergeInputs::row).
void run(benchmark::State& bs, const MergeState& st, D3DFORMAT colorFormat, D3DFORMAT depthFormat,
         bool row = false) {
    static const Inputs in;
    Image color = makeImage(colorFormat);
    Image depth = depthFormat == D3DFMT_UNKNOWN ? Image{} : makeImage(depthFormat);
    MergeTarget target{&color, depthFormat == D3DFMT_UNKNOWN ? nullptr : &depth};
    MergeInputs mi;
    mi.count = kSide;
    mi.x = in.x.data();
    mi.row = row;
    const bool fx = ps11::isFixedPoint(st.precision);
    for (int c = 0; c < 4; ++c) mi.color[c] = in.color[c].data(), mi.grid[c] = fx ? in.grid[c].data() : nullptr;
    mi.fog = in.fog.data(), mi.z = in.z.data();
    MergeStats stats;
    for (auto _ : bs) {
        for (int r = 0; r < kSide; ++r) {
            mi.y = in.y[r].data();
            mergePixels(st, mi, target, &stats);
        }
        benchmark::DoNotOptimize(color.bytes.data());
    }
    const double pixels = double(bs.iterations()) * kSide * kSide;
    bs.counters["ns/pixel"] = benchmark::Counter(pixels, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    bs.SetItemsProcessed(int64_t(pixels));
}

MergeState base(Precision p) {
    MergeState st;
    st.precision = p;
    return st;
}
MergeState blended(Precision p, D3DBLEND s, D3DBLEND d) {
    MergeState st = base(p);
    st.blend = true, st.srcBlend = s, st.dstBlend = d;
    return st;
}

void BM_store_fx8(benchmark::State& s) { run(s, base(Precision::Fx8), D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN); }
void BM_store_fx12(benchmark::State& s) { run(s, base(Precision::Fx12), D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN); }
void BM_store_float(benchmark::State& s) { run(s, base(Precision::Float), D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN); }
void BM_store_fx8_half(benchmark::State& s) { run(s, base(Precision::Fx8), D3DFMT_A16B16G16R16F, D3DFMT_UNKNOWN); }
void BM_store_float_f32(benchmark::State& s) { run(s, base(Precision::Float), D3DFMT_A32B32G32R32F, D3DFMT_UNKNOWN); }
void BM_add_fx8(benchmark::State& s) {
    run(s, blended(Precision::Fx8, D3DBLEND_ONE, D3DBLEND_ONE), D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN);
}
void BM_alpha_fx8(benchmark::State& s) {
    run(s, blended(Precision::Fx8, D3DBLEND_SRCALPHA, D3DBLEND_INVSRCALPHA), D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN);
}
void BM_alpha_fx12(benchmark::State& s) {
    run(s, blended(Precision::Fx12, D3DBLEND_SRCALPHA, D3DBLEND_INVSRCALPHA), D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN);
}
void BM_alpha_float(benchmark::State& s) {
    run(s, blended(Precision::Float, D3DBLEND_SRCALPHA, D3DBLEND_INVSRCALPHA), D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN);
}
void BM_add_float_row(benchmark::State& s) {
    run(s, blended(Precision::Float, D3DBLEND_ONE, D3DBLEND_ONE), D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN, true);
}
void BM_add_float_half(benchmark::State& s) {
    run(s, blended(Precision::Float, D3DBLEND_ONE, D3DBLEND_ONE), D3DFMT_A16B16G16R16F, D3DFMT_UNKNOWN);
}
void BM_depth_fx8_d24s8(benchmark::State& s) {
    MergeState st = base(Precision::Fx8);
    st.depthTest = st.depthWrite = true;
    st.depthFunc = D3DCMP_ALWAYS;
    run(s, st, D3DFMT_A8R8G8B8, D3DFMT_D24S8);
}
void BM_fog_alphatest_fx8(benchmark::State& s) {
    MergeState st = base(Precision::Fx8);
    st.fog = true, st.fogColor = 0x808080;
    st.alphaTest = true, st.alphaFunc = D3DCMP_GREATER, st.alphaRef = 0;
    run(s, st, D3DFMT_A8R8G8B8, D3DFMT_UNKNOWN);
}

}  // namespace

BENCHMARK(BM_store_fx8);
BENCHMARK(BM_store_fx12);
BENCHMARK(BM_store_float);
BENCHMARK(BM_store_fx8_half);
BENCHMARK(BM_store_float_f32);
BENCHMARK(BM_add_fx8);
BENCHMARK(BM_alpha_fx8);
BENCHMARK(BM_alpha_fx12);
BENCHMARK(BM_alpha_float);
BENCHMARK(BM_add_float_row);
BENCHMARK(BM_add_float_half);
BENCHMARK(BM_depth_fx8_d24s8);
BENCHMARK(BM_fog_alphatest_fx8);

BENCHMARK_MAIN();
