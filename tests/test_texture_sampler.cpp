// Unit tests of the software textures and the sampler (ps11/texture.h, ps11/texture_sampler.h):
// format decoding, mip generation, addressing, filtering and LOD selection in fx8, fx12 and
// float. Expected values are worked out by hand in the comments (docs/precision.md "Sampling",
// docs/textures.md).
#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "ps11/testfile.h"
#include "ps11/testfile_textures.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"
#include "ps11/texture_sampler_fast.h"
#include "simd_levels.h"

using namespace ps11;

namespace {

Texel word(uint32_t bits) {
    Texel t;
    t.bits = bits;
    return t;
}

Texel floats(std::initializer_list<float> v) {
    Texel t;
    for (float x : v) t.value[t.count++] = x;
    return t;
}

// A texture description with level 0 given texel by texel (rows top first, slice after slice);
// levels = 0 generates the chain.
TextureDesc makeDesc(TexFormat f, uint32_t w, uint32_t h, uint32_t d, const std::vector<Texel>& texels,
                     uint32_t levels = 1) {
    TextureDesc desc;
    desc.format = {f, 1};
    desc.width = w, desc.height = h, desc.depth = d;
    desc.sizeLine = 1;
    desc.levels = {levels, 1};
    TextureLevel l;
    l.level = 0;
    l.width = w, l.height = h, l.depth = d ? d : 1;
    l.texels = texels;
    desc.data.push_back(l);
    return desc;
}

std::vector<Texel> words(std::initializer_list<uint32_t> w) {
    std::vector<Texel> v;
    for (uint32_t x : w) v.push_back(word(x));
    return v;
}

std::shared_ptr<const Texture> build(const TextureDesc& desc) {
    std::string error;
    std::optional<Texture> t = textureFromDesc(desc, SignedDecode::Snorm, error);
    INFO(error);
    REQUIRE(t);
    return std::make_shared<const Texture>(std::move(*t));
}

std::shared_ptr<const Texture> build(TexFormat f, uint32_t w, uint32_t h, std::initializer_list<uint32_t> texels,
                                     uint32_t d = 0) {
    return build(makeDesc(f, w, h, d, words(texels)));
}

struct Result {
    std::array<std::vector<int32_t>, 4> g;
    std::array<std::vector<float>, 4> f;
};

Result run(TextureSampler& s, Precision p, const std::vector<float>& u, const std::vector<float>& v,
           const std::vector<float>& w = {}, bool quads = false, int stage = 0, const LevelChoice* levels = nullptr) {
    Result r;
    SampleRequest req;
    req.stage = stage;
    req.count = int(u.size());
    req.quads = quads;
    req.levels = levels;
    req.dims = w.empty() ? 2 : 3;
    req.u = u.data();
    req.v = v.data();
    req.w = w.empty() ? nullptr : w.data();
    req.precision = p;
    SampleResult out;
    for (int c = 0; c < 4; ++c) {
        r.g[size_t(c)].assign(u.size(), -999);
        r.f[size_t(c)].assign(u.size(), -999.0f);
        out.grid[c] = r.g[size_t(c)].data();
        out.value[c] = r.f[size_t(c)].data();
    }
    s.sample(req, out);
    return r;
}

// Red channel of one lane.
int32_t red(TextureSampler& s, Precision p, float u, float v) { return run(s, p, {u}, {v}).g[0][0]; }
float redF(TextureSampler& s, float u, float v) { return run(s, Precision::Float, {u}, {v}).f[0][0]; }

SamplerState state(Filter minMag, TextureAddress a, Filter mip = Filter::None) {
    SamplerState st;
    st.minFilter = st.magFilter = minMag;
    st.mipFilter = mip;
    st.addressU = st.addressV = st.addressW = a;
    return st;
}

using G = std::array<int32_t, 4>;

}  // namespace

TEST_CASE("texture: 8-bit formats decode to bytes, missing channels read 1 (A8: rgb 0)", "[sampler]") {
    // A8R8G8B8 0x80402010: a = 0x80, r = 0x40, g = 0x20, b = 0x10.
    auto t = build(TexFormat::A8R8G8B8, 1, 1, {0x80402010});
    CHECK(t->storage() == TexelStorage::Unorm8);
    CHECK(t->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{64, 32, 16, 128});
    CHECK(t->texelGrid(0, 0, 0, 0, Precision::Fx12) == G{1024, 512, 256, 2048});  // n * 16
    CHECK(t->texelValue(0, 0, 0)[0] == float(64.0 / 255.0));
    // X8R8G8B8: the X byte is ignored, alpha = 1.
    CHECK(build(TexFormat::X8R8G8B8, 1, 1, {0x00ff8000})->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{255, 128, 0, 255});
    // A8: (0, 0, 0, A) (spec §6.4).
    CHECK(build(TexFormat::A8, 1, 1, {0x7f})->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{0, 0, 0, 127});
    // L8: (L, L, L, 1).
    CHECK(build(TexFormat::L8, 1, 1, {0x33})->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{51, 51, 51, 255});
    // A8L8 0x8011: L = 0x11 = 17, A = 0x80.
    CHECK(build(TexFormat::A8L8, 1, 1, {0x8011})->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{17, 17, 17, 128});
}

TEST_CASE("texture: signed formats map b to b/den clamped, grid round_half_even(b*G/den)", "[sampler]") {
    // V8U8 0x817f: U = 127 -> 1 (255), V = -127 -> -1; b = a = 1.
    auto v8 = build(TexFormat::V8U8, 3, 1, {0x817f, 0x8040, 0x0000});
    CHECK(v8->storage() == TexelStorage::Decoded);
    CHECK(v8->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{255, -255, 255, 255});
    // 0x8040: U = 64 -> 64*255/127 = 128 + 64/127 -> 129; fx12 64*4080/127 = 2056 + 8/127 -> 2056.
    // V = 0x80 = -128 -> -128/127 clamped to -1.
    CHECK(v8->texelGrid(0, 1, 0, 0, Precision::Fx8) == G{129, -255, 255, 255});
    CHECK(v8->texelGrid(0, 1, 0, 0, Precision::Fx12) == G{2056, -4080, 4080, 4080});
    CHECK(v8->texelValue(0, 1, 0)[0] == float(64.0 / 127.0));
    CHECK(v8->texelValue(0, 1, 0)[1] == -1.0f);

    // L6V5U5: U bits 0-4, V 5-9 (5-bit signed, /15), L 10-15 (6-bit unsigned, /63), a = 1.
    // 0xfe0f: U = 15 -> 1, V = 0b10000 = -16 -> clamped -1, L = 63 -> 1.
    // 0x57a5 = 5 | 29 << 5 | 21 << 10: U = 5/15 = 1/3 -> 85, V = 29 - 32 = -3 -> -0.2 -> -51, L = 21/63 -> 85.
    auto l6 = build(TexFormat::L6V5U5, 2, 1, {0xfe0f, 0x57a5});
    CHECK(l6->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{255, -255, 255, 255});
    CHECK(l6->texelGrid(0, 1, 0, 0, Precision::Fx8) == G{85, -51, 85, 255});
    CHECK(l6->texelGrid(0, 1, 0, 0, Precision::Fx12) == G{1360, -816, 1360, 4080});

    // X8L8V8U8 0xab80ff01: U = 1 -> 255/127 = 2.008 -> 2 (fx12 32.13 -> 32), V = -1 -> -2,
    // L = 0x80 unsigned /255 -> 128 exactly, X ignored -> a = 1.
    auto x8 = build(TexFormat::X8L8V8U8, 1, 1, {0xab80ff01});
    CHECK(x8->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{2, -2, 128, 255});
    CHECK(x8->texelGrid(0, 0, 0, 0, Precision::Fx12) == G{32, -32, 2048, 4080});

    // Q8W8V8U8 0x7f81c040: U = 64 -> 129, V = -64 -> -129, W = -127 -> -255, Q = 127 -> 255.
    auto q8 = build(TexFormat::Q8W8V8U8, 1, 1, {0x7f81c040});
    CHECK(q8->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{129, -129, -255, 255});

    // V16U16 0x80007fff: U = 32767 -> 1, V = -32768 -> clamped -1. 0x00004000: U = 16384 ->
    // 16384*255/32767 = 127 + 16511/32767 -> 128; fx12 16384*4080/32767 = 2040 + 2040/32767 -> 2040.
    auto v16 = build(TexFormat::V16U16, 2, 1, {0x80007fff, 0x00004000});
    CHECK(v16->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{255, -255, 255, 255});
    CHECK(v16->texelGrid(0, 1, 0, 0, Precision::Fx8) == G{128, 0, 255, 255});
    CHECK(v16->texelGrid(0, 1, 0, 0, Precision::Fx12) == G{2040, 0, 4080, 4080});
}

TEST_CASE("texture: float formats (half rounding, R32F, grid ties to even)", "[sampler]") {
    // A16B16G16R16F stores halves: 0.1 -> 1638 * 2^-14 = 0.0999755859375; alpha not written -> 1.
    auto h = build(makeDesc(TexFormat::A16B16G16R16F, 1, 1, 0, {floats({0.1f, 2.0f, -0.5f})}));
    Vec4 hv = h->texelValue(0, 0, 0);
    CHECK(hv[0] == 0.0999755859375f);
    CHECK(hv[1] == 2.0f);
    CHECK(hv[3] == 1.0f);
    // fx8: 0.09998*255 = 25.49 -> 25; 2*255 = 510; -0.5*255 = -127.5 -> tie to even -128.
    CHECK(h->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{25, 510, -128, 255});
    CHECK(h->texelGrid(0, 0, 0, 0, Precision::Fx12) == G{408, 8160, -2040, 4080});  // 407.9 -> 408
    // A32B32G32R32F: 63.75 -> 64, 127.5 -> 128 (even), 191.25 -> 191.
    auto f = build(makeDesc(TexFormat::A32B32G32R32F, 1, 1, 0, {floats({0.25f, 0.5f, 0.75f, 1.0f})}));
    CHECK(f->texelGrid(0, 0, 0, 0, Precision::Fx8) == G{64, 128, 191, 255});
    // R32F: (r, 1, 1, 1).
    auto r = build(makeDesc(TexFormat::R32F, 1, 1, 0, {floats({0.3f})}));
    CHECK(r->texelValue(0, 0, 0) == Vec4{0.3f, 1.0f, 1.0f, 1.0f});
    CHECK(r->texelGrid(0, 0, 0, 0, Precision::Fx8)[0] == 77);  // 0.3f*255 = 76.500003 -> 77
    // Half helper: overflow and subnormals.
    CHECK(roundToHalf(65519.0f) == 65504.0f);
    CHECK(std::isinf(roundToHalf(65520.0f)));
    CHECK(roundToHalf(3.0f * 0x1p-25f) == 0x1p-23f);  // 1.5 quanta of 2^-24 -> 2 (even)
}

TEST_CASE("texture: textureFromDesc errors", "[sampler]") {
    std::string error;
    auto fails = [&](const TextureDesc& d, const char* fragment) {
        error.clear();
        CHECK_FALSE(textureFromDesc(d, SignedDecode::Snorm, error));
        INFO(error);
        CHECK(error.find(fragment) != std::string::npos);
    };
    TextureDesc ok = makeDesc(TexFormat::L8, 2, 2, 0, words({1, 2, 3, 4}));
    CHECK(textureFromDesc(ok, SignedDecode::Snorm, error));

    TextureDesc noSize = ok;
    noSize.width = 0;
    fails(noSize, "no size");
    TextureDesc tooMany = ok;
    tooMany.levels = {3, 1};  // 2x2 has 2 levels
    fails(tooMany, "more than the texture has");
    TextureDesc missing = ok;
    missing.levels = {2, 1};
    fails(missing, "no data for level 1");
    TextureDesc shortLevel = makeDesc(TexFormat::L8, 2, 2, 0, words({1, 2, 3}));
    fails(shortLevel, "has 3 texels, expected 4");
    fails(makeDesc(TexFormat::L8, 1, 1, 0, {floats({0.5f})}), "packed texel words");
    fails(makeDesc(TexFormat::R32F, 1, 1, 0, words({1})), "float texels");
    fails(makeDesc(TexFormat::L8, 1, 1, 0, words({0x100})), "does not fit");
    fails(makeDesc(TexFormat::L8, 1, 1, 0, {}), "has 0 texels");
    // 16384 x 16384 float texels need 16 GiB: refused before any allocation.
    TextureDesc huge = makeDesc(TexFormat::A32B32G32R32F, 16384, 16384, 0, {});
    huge.data[0].hasFill = true;
    huge.data[0].fill = floats({1.0f});
    fails(huge, "more than the limit");
    TextureDesc tooWide = ok;
    tooWide.width = 20000;
    fails(tooWide, "beyond the limits");
    TextureDesc noLevel0 = ok;
    noLevel0.data.clear();
    fails(noLevel0, "no data for level 0");
}

TEST_CASE("texture: parsed .ps11test sections build textures and sampler state", "[sampler]") {
    const char* text =
        "[texture 1]\nsize 2 1\nformat V8U8\nlevel 0\n0x007f 0x8100\n"
        "[sampler 1]\nfilter linear mip point\naddress clamp wrap\nborder 0xff808080\n";
    TestFile file;
    std::vector<TestFileError> errors;
    parseTestFile(text, "t.ps11test", file, errors);
    REQUIRE(file.texture(1));
    auto t = build(*file.texture(1));
    CHECK(t->texelGrid(0, 1, 0, 0, Precision::Fx8) == G{0, -255, 255, 255});
    REQUIRE(file.sampler(1));
    SamplerState s = samplerStateFromDesc(*file.sampler(1));
    CHECK(s.minFilter == Filter::Linear);
    CHECK(s.magFilter == Filter::Linear);
    CHECK(s.mipFilter == Filter::Point);
    CHECK(s.addressU == TextureAddress::Clamp);
    CHECK(s.addressV == TextureAddress::Wrap);
    CHECK(s.border[3] == 1.0f);
    SamplerState d = samplerStateFromDesc(SamplerDesc{});  // D3D9 defaults
    CHECK(d.minFilter == Filter::Point);
    CHECK(d.addressU == TextureAddress::Wrap);
}

TEST_CASE("texture: mip generation is a box filter rounded half-even", "[sampler]") {
    // 4x4 L8; 2x2 blocks: (0 0 0 2) = 0.5 -> 0 (even); (1 1 1 2) = 1.25 -> 1;
    // (2 2 2 4) = 2.5 -> 2 (even); (3 3 3 4) = 3.25 -> 3. Level 2: (0 1 2 3) = 1.5 -> 2 (even).
    auto t = build(makeDesc(TexFormat::L8, 4, 4, 0, words({0, 0, 1, 1, 0, 2, 1, 2, 2, 2, 3, 3, 2, 4, 3, 4}), 0));
    REQUIRE(t->levelCount() == 3);
    CHECK(t->level(1).width == 2);
    CHECK(t->level(2).width == 1);
    CHECK(t->texelGrid(1, 0, 0, 0, Precision::Fx8)[0] == 0);
    CHECK(t->texelGrid(1, 1, 0, 0, Precision::Fx8)[0] == 1);
    CHECK(t->texelGrid(1, 0, 1, 0, Precision::Fx8)[0] == 2);
    CHECK(t->texelGrid(1, 1, 1, 0, Precision::Fx8)[0] == 3);
    CHECK(t->texelGrid(2, 0, 0, 0, Precision::Fx8)[0] == 2);
    CHECK(t->texelGrid(2, 0, 0, 0, Precision::Fx8)[3] == 255);  // alpha stays 1

    // 4x1: the height-1 axis repeats its row. (10 20 10 20) = 15, (30 41 30 41) = 35.5 -> 36;
    // level 2: (15 36 15 36) = 25.5 -> 26.
    auto r = build(makeDesc(TexFormat::L8, 4, 1, 0, words({10, 20, 30, 41}), 0));
    REQUIRE(r->levelCount() == 3);
    CHECK(r->texelGrid(1, 1, 0, 0, Precision::Fx8)[0] == 36);
    CHECK(r->texelGrid(2, 0, 0, 0, Precision::Fx8)[0] == 26);

    // Volume 2x2x2 -> 1x1x1: (0 + 1 + ... + 7) / 8 = 3.5 -> 4.
    auto v = build(makeDesc(TexFormat::L8, 2, 2, 2, words({0, 1, 2, 3, 4, 5, 6, 7}), 0));
    REQUIRE(v->levelCount() == 2);
    CHECK(v->texelGrid(1, 0, 0, 0, Precision::Fx8)[0] == 4);

    // V8U8 in the raw signed bytes: U (-1 -2 1 0) = -0.5 -> 0; V (-3 0 0 0) = -0.75 -> -1,
    // whose grid is -255/127 -> -2.
    auto s = build(makeDesc(TexFormat::V8U8, 2, 2, 0, words({0xfdff, 0x00fe, 0x0001, 0x0000}), 0));
    CHECK(s->texelGrid(1, 0, 0, 0, Precision::Fx8) == G{0, -2, 255, 255});

    // Floats average exactly: (1 2 3 4.5) / 4 = 2.625.
    auto f = build(makeDesc(TexFormat::R32F, 2, 2, 0, {floats({1}), floats({2}), floats({3}), floats({4.5f})}, 0));
    CHECK(f->texelValue(1, 0, 0)[0] == 2.625f);
}

TEST_CASE("sampler: point sampling at texel centres and edges", "[sampler]") {
    TextureSampler s;
    s.bind(0, build(TexFormat::L8, 4, 1, {0x00, 0x55, 0xaa, 0xff}));
    s.setSamplerState(0, state(Filter::Point, TextureAddress::Clamp));
    CHECK(red(s, Precision::Fx8, 0.125f, 0.5f) == 0);     // centre of texel 0
    CHECK(red(s, Precision::Fx8, 0.2499f, 0.5f) == 0);    // floor(0.9996) = 0
    CHECK(red(s, Precision::Fx8, 0.25f, 0.5f) == 0x55);   // edge: floor(1.0) = 1 (ties go up)
    CHECK(red(s, Precision::Fx8, 0.99f, 0.5f) == 0xff);
    CHECK(red(s, Precision::Fx8, 1.0f, 0.5f) == 0xff);    // floor(4) = 4, clamped to 3
    CHECK(red(s, Precision::Fx12, 0.3f, 0.5f) == 0x55 * 16);
    CHECK(redF(s, 0.6f, 0.5f) == float(170.0 / 255.0));
    s.setSamplerState(0, state(Filter::Point, TextureAddress::Wrap));
    CHECK(red(s, Precision::Fx8, 1.0f, 0.5f) == 0);       // 4 wraps to 0
}

TEST_CASE("sampler: bilinear 8-bit weights, ties to even, fx8 vs fx12 vs float", "[sampler]") {
    TextureSampler s;
    s.bind(0, build(TexFormat::L8, 2, 1, {0x00, 0xff}));
    for (bool fast : {true, false}) {
        s.setFastPath(fast);
        for (TextureAddress a : {TextureAddress::Clamp, TextureAddress::Mirror}) {
            s.setSamplerState(0, state(Filter::Linear, a));
            INFO("fast " << fast << " mode " << int(a));
            // u = 0.5: x = 0.5, w = 128: 255 * 128/256 = 127.5 -> 128 (even); fx12 2040 exactly.
            CHECK(red(s, Precision::Fx8, 0.5f, 0.5f) == 128);
            CHECK(red(s, Precision::Fx12, 0.5f, 0.5f) == 2040);
            CHECK(redF(s, 0.5f, 0.5f) == 0.5f);
            // f = 3/512 (u = 0.25 + 3/1024): w = round(1.5) = 2; 2*255/256 = 1.99 -> 2 (unquantised
            // 3*255/512 = 1.49 would give 1); fx12 2*4080/256 = 31.875 -> 32; float f itself.
            CHECK(red(s, Precision::Fx8, 0.25f + 3.0f / 1024, 0.5f) == 2);
            CHECK(red(s, Precision::Fx12, 0.25f + 3.0f / 1024, 0.5f) == 32);
            CHECK(redF(s, 0.25f + 3.0f / 1024, 0.5f) == 3.0f / 512);
            // f = 255.5/256 (u = 0.7490234375): w = 255.5 -> 256 (even): texel 1 alone = 255
            // (unquantised 254.5 would round to 254).
            CHECK(red(s, Precision::Fx8, 0.7490234375f, 0.5f) == 255);
            // f = 1/512: w = 0.5 -> 0 (even): texel 0.
            CHECK(red(s, Precision::Fx8, 0.25f + 1.0f / 1024, 0.5f) == 0);
        }
    }
    // 0 and 253 half way: 126.5 -> 126 (even).
    s.bind(1, build(TexFormat::L8, 2, 1, {0x00, 0xfd}));
    s.setSamplerState(1, state(Filter::Linear, TextureAddress::Clamp));
    CHECK(run(s, Precision::Fx8, {0.5f}, {0.5f}, {}, false, 1).g[0][0] == 126);
    // 2x2 (0 255 / 255 0) at the centre: each weight 128*128: 510/4 = 127.5 -> 128.
    s.bind(2, build(TexFormat::L8, 2, 2, {0x00, 0xff, 0xff, 0x00}));
    s.setSamplerState(2, state(Filter::Linear, TextureAddress::Wrap));
    CHECK(run(s, Precision::Fx8, {0.5f}, {0.5f}, {}, false, 2).g[0][0] == 128);
    // Signed texels filter in their grid values: U 127 (255) and 0: 127.5 -> 128; V -127 and 0.
    s.bind(3, build(TexFormat::V8U8, 2, 1, {0x817f, 0x0000}));
    s.setSamplerState(3, state(Filter::Linear, TextureAddress::Clamp));
    Result r = run(s, Precision::Fx8, {0.5f}, {0.5f}, {}, false, 3);
    CHECK(r.g[0][0] == 128);
    CHECK(r.g[1][0] == -128);  // -127.5 -> -128 (even)
    CHECK(run(s, Precision::Float, {0.5f}, {0.5f}, {}, false, 3).f[1][0] == -0.5f);
}

TEST_CASE("sampler: address modes map every texel index", "[sampler]") {
    TextureSampler s;
    s.bind(0, build(TexFormat::L8, 4, 1, {10, 20, 30, 40}));
    auto at = [&](TextureAddress a, float u) {
        SamplerState st = state(Filter::Point, a);
        st.addressV = TextureAddress::Clamp;
        st.border = {0.2f, 0.4f, 0.6f, 0.8f};
        s.setSamplerState(0, st);
        return run(s, Precision::Fx8, {u}, {0.5f}).g;
    };
    // u = -0.1: floor(-0.4) = -1. wrap -> 3; mirror -> 0; clamp -> 0; mirroronce -> 0; border.
    CHECK(at(TextureAddress::Wrap, -0.1f)[0][0] == 40);
    CHECK(at(TextureAddress::Mirror, -0.1f)[0][0] == 10);
    CHECK(at(TextureAddress::Clamp, -0.1f)[0][0] == 10);
    CHECK(at(TextureAddress::MirrorOnce, -0.1f)[0][0] == 10);
    auto b = at(TextureAddress::Border, -0.1f);  // border 0.2 0.4 0.6 0.8 -> 51 102 153 204
    CHECK(G{b[0][0], b[1][0], b[2][0], b[3][0]} == G{51, 102, 153, 204});
    // u = 1.3: floor(5.2) = 5. wrap -> 1; mirror -> 2*4-1-5 = 2; clamp -> 3; mirroronce -> 3.
    CHECK(at(TextureAddress::Wrap, 1.3f)[0][0] == 20);
    CHECK(at(TextureAddress::Mirror, 1.3f)[0][0] == 30);
    CHECK(at(TextureAddress::Clamp, 1.3f)[0][0] == 40);
    CHECK(at(TextureAddress::MirrorOnce, 1.3f)[0][0] == 40);
    CHECK(at(TextureAddress::Border, 1.3f)[0][0] == 51);
    // u = -1.3: floor(-5.2) = -6. wrap -> 2; mirror: -1.3 mod 2 = 0.7, not flipped -> 2;
    // mirroronce: |u| = 1.3 -> clamped to 3.
    CHECK(at(TextureAddress::Wrap, -1.3f)[0][0] == 30);
    CHECK(at(TextureAddress::Mirror, -1.3f)[0][0] == 30);
    CHECK(at(TextureAddress::MirrorOnce, -1.3f)[0][0] == 40);
    // Mirror u = 0.8 + 1 = 1.8: 2 - 1.8 = 0.2 -> texel 0.
    CHECK(at(TextureAddress::Mirror, 1.8f)[0][0] == 10);

    // Bilinear at u = 0 with border: x = -0.5, taps border (51) and texel 0 (10), w = 128:
    // (51 + 10) / 2 = 30.5 -> 30 (even). fx12: (816 + 160) / 2 = 488.
    SamplerState st = state(Filter::Linear, TextureAddress::Border);
    st.border = {0.2f, 0.4f, 0.6f, 0.8f};
    s.setSamplerState(0, st);
    CHECK(red(s, Precision::Fx8, 0.0f, 0.5f) == 30);
    CHECK(red(s, Precision::Fx12, 0.0f, 0.5f) == 488);
    CHECK(redF(s, 0.0f, 0.5f) == Approx(0.5f * 0.2f + 0.5f * (10.0f / 255)));
    // Border colour on the grid: 0.5 -> 127.5 -> 128 (even), fx12 2040.
    st.border = {0.5f, 0.5f, 0.5f, 0.5f};
    s.setSamplerState(0, st);
    CHECK(red(s, Precision::Fx8, -2.0f, 0.5f) == 128);
    CHECK(red(s, Precision::Fx12, -2.0f, 0.5f) == 2040);

    // Nonsense coordinates never crash and stay in the texture.
    for (TextureAddress a : {TextureAddress::Wrap, TextureAddress::Mirror, TextureAddress::Clamp,
                             TextureAddress::Border, TextureAddress::MirrorOnce})
        for (Filter f : {Filter::Point, Filter::Linear}) {
            s.setSamplerState(0, state(f, a));
            const float inf = std::numeric_limits<float>::infinity();
            Result r = run(s, Precision::Fx8, {std::nanf(""), inf, -inf, 1e30f, -3e38f, 16777216.0f},
                           {0.5f, std::nanf(""), 1e20f, -inf, 0.5f, 3e38f});
            for (int i = 0; i < 6; ++i) CHECK((r.g[0][size_t(i)] >= 0 && r.g[0][size_t(i)] <= 40));
            r = run(s, Precision::Float, {std::nanf("")}, {std::nanf("")});
            CHECK(r.f[0][0] >= 0.0f);
        }
    // NaN samples as coordinate 0: wrap point -> texel 0.
    s.setSamplerState(0, state(Filter::Point, TextureAddress::Wrap));
    CHECK(red(s, Precision::Fx8, std::nanf(""), 0.5f) == 10);
}

TEST_CASE("sampler: volume textures, point and trilinear", "[sampler]") {
    // 2x2x2 L8: slice 0 = (0 64 / 128 192), slice 1 all 255.
    TextureSampler s;
    s.bind(0, build(TexFormat::L8, 2, 2, {0, 64, 128, 192, 255, 255, 255, 255}, 2));
    s.setSamplerState(0, state(Filter::Point, TextureAddress::Clamp));
    auto at = [&](Precision p, float u, float v, float w) { return run(s, p, {u}, {v}, {w}); };
    CHECK(at(Precision::Fx8, 0.75f, 0.75f, 0.25f).g[0][0] == 192);  // slice 0, texel (1, 1)
    CHECK(at(Precision::Fx8, 0.25f, 0.25f, 0.75f).g[0][0] == 255);  // slice 1
    s.setSamplerState(0, state(Filter::Linear, TextureAddress::Clamp));
    // Centre: every weight 128^3 / 2^24 = 1/8: (0 + 64 + 128 + 192 + 4*255) / 8 = 175.5 -> 176.
    CHECK(at(Precision::Fx8, 0.5f, 0.5f, 0.5f).g[0][0] == 176);
    CHECK(at(Precision::Fx12, 0.5f, 0.5f, 0.5f).g[0][0] == 2808);  // 175.5 * 16 exactly
    CHECK(at(Precision::Float, 0.5f, 0.5f, 0.5f).f[0][0] == Approx(175.5 / 255));
    // w at slice 0's centre (0.25): only slice 0: (0 + 64 + 128 + 192) / 4 = 96.
    CHECK(at(Precision::Fx8, 0.5f, 0.5f, 0.25f).g[0][0] == 96);
    // A 2D request (no w) on a volume samples w = 0: clamped to slice 0.
    CHECK(run(s, Precision::Fx8, {0.5f}, {0.5f}).g[0][0] == 96);
    uint64_t before = s.texelsFetched();
    at(Precision::Fx8, 0.5f, 0.5f, 0.5f);
    CHECK(s.texelsFetched() - before == 8);
}

TEST_CASE("sampler: LOD from quads selects mip levels", "[sampler]") {
    // 8x8 L8 with 4 levels filled 0x10, 0x20, 0x30, 0x40.
    TextureDesc d = makeDesc(TexFormat::L8, 8, 8, 0, {}, 4);
    d.data.clear();
    for (uint32_t k = 0; k < 4; ++k) {
        TextureLevel l;
        l.level = k;
        l.width = l.height = 8 >> k;
        l.hasFill = true;
        l.fill = word(0x10 * (k + 1));
        d.data.push_back(l);
    }
    TextureSampler s;
    s.bind(0, build(d));
    s.setSamplerState(0, state(Filter::Point, TextureAddress::Wrap, Filter::Point));
    // One quad: TL, TR = TL + (du, dv), BL = TL + (du2, dv2), BR. Derivatives in texels of level 0.
    auto quad = [&](float du, float dv, float du2, float dv2, Precision p = Precision::Fx8) {
        const float u0 = 0.3f, v0 = 0.3f;
        Result r = run(s, p, {u0, u0 + du, u0 + du2, u0 + du + du2}, {v0, v0 + dv, v0 + dv2, v0 + dv + dv2}, {},
                       true);
        for (int i = 1; i < 4; ++i) CHECK(r.g[0][size_t(i)] == r.g[0][0]);  // one LOD per quad
        return r.g[0][0];
    };
    CHECK(quad(1.0f / 8, 0, 0, 1.0f / 8) == 0x10);     // rho = 1: LOD 0 -> level 0
    CHECK(quad(2.0f / 8, 0, 0, 2.0f / 8) == 0x20);     // 2x minified: LOD 1 -> level 1
    CHECK(quad(4.0f / 8, 0, 0, 4.0f / 8) == 0x30);     // LOD 2
    CHECK(quad(16.0f / 8, 0, 0, 16.0f / 8) == 0x40);   // LOD 4, clamped to the last level 3
    CHECK(quad(1.0f / 16, 0, 0, 1.0f / 16) == 0x10);   // magnified
    CHECK(quad(1.0f / 8, 0, 0, 4.0f / 8) == 0x30);     // rho = max(|dx|, |dy|) = 4
    CHECK(quad(0, 3.0f / 8, 4.0f / 8, 0) == 0x30);     // vectors: |(0, 3)| = 3, |(4, 0)| = 4
    // |dx| = |(3, 4)| = 5: LOD log2(5) = 2.32 -> nearest level 2.
    CHECK(quad(3.0f / 8, 4.0f / 8, 0, 0) == 0x30);
    // Nearest level: LOD 1.4 -> 1, LOD 1.6 -> 2.
    CHECK(quad(float(std::exp2(1.4) / 8), 0, 0, 0) == 0x20);
    CHECK(quad(float(std::exp2(1.6) / 8), 0, 0, 0) == 0x30);
    // Without quads: level 0.
    CHECK(run(s, Precision::Fx8, {0.3f, 0.9f, 0.3f, 0.9f}, {0.3f, 0.3f, 0.9f, 0.9f}).g[0][0] == 0x10);
    // Mip filter none: level 0 however minified.
    s.setSamplerState(0, state(Filter::Point, TextureAddress::Wrap, Filter::None));
    CHECK(quad(4.0f / 8, 0, 0, 4.0f / 8) == 0x10);
}

TEST_CASE("sampler: mag filter at LOD <= 0, min filter beyond", "[sampler]") {
    TextureSampler s;
    s.bind(0, build(TexFormat::L8, 2, 1, {0x00, 0xff}));
    SamplerState st = state(Filter::Point, TextureAddress::Clamp);
    st.magFilter = Filter::Linear;
    s.setSamplerState(0, st);
    // du = 0.5 on a 2-wide texture: rho = 1, LOD 0 -> mag (linear): 127.5 -> 128.
    CHECK(run(s, Precision::Fx8, {0.5f, 1.0f, 0.5f, 1.0f}, {0.5f, 0.5f, 0.5f, 0.5f}, {}, true).g[0][0] == 128);
    // du = 1: rho = 2, LOD 1 -> min (point): floor(0.5 * 2) = texel 1.
    CHECK(run(s, Precision::Fx8, {0.5f, 1.5f, 0.5f, 1.5f}, {0.5f, 0.5f, 0.5f, 0.5f}, {}, true).g[0][0] == 255);
    // Without quads the mag filter applies.
    CHECK(red(s, Precision::Fx8, 0.5f, 0.5f) == 128);
    // A partial quad (3 lanes) still works.
    CHECK(run(s, Precision::Fx8, {0.5f, 1.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {}, true).g[0][0] == 255);
}

TEST_CASE("sampler: linear mip filter blends two levels, rounding once", "[sampler]") {
    // 4x4 L8: level 0 columns alternate 0 3 0 3; level 1 (2x2) all 1; level 2 all 9.
    TextureDesc d = makeDesc(TexFormat::L8, 4, 4, 0, words({0, 3, 0, 3, 0, 3, 0, 3, 0, 3, 0, 3, 0, 3, 0, 3}), 3);
    for (uint32_t k = 1; k < 3; ++k) {
        TextureLevel l;
        l.level = k;
        l.width = l.height = 4 >> k;
        l.hasFill = true;
        l.fill = word(k == 1 ? 1 : 9);
        d.data.push_back(l);
    }
    TextureSampler s;
    s.bind(0, build(d));
    s.setSamplerState(0, state(Filter::Linear, TextureAddress::Clamp, Filter::Linear));
    // TL at u = 0.25 (x = 0.5 between columns 0 and 1, w = 128), v = 0.125 (row 0's centre).
    // du = sqrt(2)/4: rho = sqrt(2), LOD 0.5 (+ float error ~1e-8): mip weight 128.
    // Level 0 = (0 + 3) / 2 = 1.5, level 1 = 1: (1.5 + 1) / 2 = 1.25 -> 1. Rounding each level
    // first would give round(round(1.5) + 1) / 2) = round(1.5) = 2.
    const float du = float(std::sqrt(2.0) / 4);
    auto quad = [&](Precision p, float d) {
        return run(s, p, {0.25f, 0.25f + d, 0.25f, 0.25f + d}, {0.125f, 0.125f, 0.125f, 0.125f}, {}, true);
    };
    CHECK(quad(Precision::Fx8, du).g[0][0] == 1);
    CHECK(quad(Precision::Fx12, du).g[0][0] == 20);  // 1.25 * 16 exactly
    CHECK(quad(Precision::Float, du).f[0][0] == Approx(1.25 / 255));
    // LOD 1.25 (rho = 2^1.25): levels 1 and 2, weight 64: (192 * 1 + 64 * 9) / 256 = 3.
    const float du2 = float(std::exp2(1.25) / 4);
    CHECK(quad(Precision::Fx8, du2).g[0][0] == 3);
    CHECK(quad(Precision::Float, du2).f[0][0] == Approx(3.0 / 255));
    // LOD 3 is beyond the last level (2): level 2 alone.
    CHECK(quad(Precision::Fx8, 2.0f).g[0][0] == 9);
    // Magnified: level 0 alone (1.5 -> 2 even).
    CHECK(quad(Precision::Fx8, 0.1f).g[0][0] == 2);
    uint64_t before = s.texelsFetched();
    quad(Precision::Fx8, du);
    CHECK(s.texelsFetched() - before == 4 * 8);  // two bilinear levels per lane
}

TEST_CASE("sampler: chooseLevel equals its definition at the edges of every decision", "[sampler]") {
    // The definition (docs/textures.md "Level of detail") written plainly: LOD = ½·log2(rho²), a
    // NaN LOD is 0; mag filter at LOD <= 0, else the min filter; point: floor(LOD + ½); linear:
    // floor(LOD) and the 8-bit (fx, and 8-bit weights) or float weight of its fraction.
    auto model = [](int levels, const SamplerState& st, double rho2, bool eight) {
        double lod = 0.5 * std::log2(rho2);
        if (std::isnan(lod)) lod = 0.0;
        LevelChoice c;
        if (lod > 0.0 && levels > 1) {
            if (st.mipFilter == Filter::Point) {
                const double n = std::floor(lod + 0.5);
                c.level0 = n >= double(levels - 1) ? levels - 1 : int(n);
            } else if (st.mipFilter == Filter::Linear) {
                const double a = std::floor(lod);
                if (a >= double(levels - 1)) {
                    c.level0 = levels - 1;
                } else {
                    c.level0 = int(a), c.level1 = c.level0 + 1;
                    const double frac = lod - a;
                    if (eight) {
                        c.mipW = int32_t(std::nearbyint(frac * 256.0));
                        if (c.mipW == 256) c.level0 = c.level1;
                        c.slots = c.mipW == 0 || c.mipW == 256 ? 1 : 2;
                        c.mipF = float(c.mipW) / 256.0f;
                    } else {
                        c.mipF = float(frac);
                        c.slots = c.mipF == 0.0f ? 1 : 2;
                    }
                }
            }
        }
        auto linear = [](Filter f) { return f == Filter::Linear; };
        c.linear = linear(lod > 0.0 ? st.minFilter : st.magFilter);
        return c;
    };
    // rho² at and one step either side of every LOD of the form k/512 (the decisions' edges: whole
    // levels, half levels, the 8-bit weights' ties), then random values, zero, inf and NaN.
    std::vector<double> rho2s = {0.0, -0.0, 1.0, std::nextafter(1.0, 2.0), std::nextafter(1.0, 0.0),
                                 std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN(),
                                 std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min()};
    for (int k = -64; k <= 16 * 512; ++k) {
        const double r = std::exp2(2.0 * k / 512.0);
        for (double x : {r, std::nextafter(r, 0.0), std::nextafter(r, INFINITY)}) rho2s.push_back(x);
    }
    std::mt19937 rng(31);
    for (int i = 0; i < 20000; ++i) rho2s.push_back(std::exp2(std::uniform_real_distribution<double>(-4, 36)(rng)));
    int bad = 0;
    int64_t decided = 0, leftToChoose = 0;
    for (int levels : {1, 2, 5, 12})
        for (Filter mip : {Filter::None, Filter::Point, Filter::Linear})
            for (Filter minF : {Filter::Point, Filter::Linear})
                for (Filter magF : {Filter::Point, Filter::Linear}) {
                    TextureDesc d = makeDesc(TexFormat::L8, 1u << 11, 1, 0, {}, uint32_t(levels));
                    d.data.clear();
                    for (int k = 0; k < levels; ++k) {
                        TextureLevel l;
                        l.level = uint32_t(k);
                        l.width = (1u << 11) >> k, l.height = 1;
                        l.hasFill = true;
                        l.fill = word(0);
                        d.data.push_back(l);
                    }
                    auto tex = build(d);
                    REQUIRE(tex->levelCount() == levels);
                    SamplerState st = state(minF, TextureAddress::Wrap, mip);
                    st.magFilter = magF;
                    for (bool eight : {true, false})
                        for (double r : rho2s) {
                            const LevelChoice want = model(levels, st, r, eight);
                            // The two derivatives either way round: rho² is the larger.
                            const LevelChoice got = chooseLevel(*tex, st, r, r * 0.25, eight, false);
                            const LevelChoice got2 = chooseLevel(*tex, st, 0.0, r, false, eight);
                            if (!(got == want && got2 == want) && bad++ < 5)
                                FAIL_CHECK("rho2 " << r << " levels " << levels << ": level " << got.level0 << "/"
                                                   << got.level1 << " w " << got.mipW << ", want " << want.level0
                                                   << "/" << want.level1 << " w " << want.mipW);
                        }
                    // The fast paths' kernel (8-bit weights) over quads TL (0, 0), TR (s, 0), BL (0, s / 3)
                    // (or the other way round) of the same texture, 2048 texels wide: rho² = (2048·s)²
                    // at and around each value above; the quads it decides, as quadLevel decides
                    // them, and its rho² for those it leaves to chooseLevel.
                    fastpath::QuadLevelRun run;
                    run.levels = levels, run.mipFilter = mip;
                    run.minLinear = minF == Filter::Linear, run.magLinear = magF == Filter::Linear;
                    run.width = 2048, run.height = 1;
                    constexpr int kSpan = 70;  // (the kernel takes 16 quads of it)
                    std::vector<float> u, v;
                    for (size_t i = 0; i < rho2s.size(); i += 3) {
                        const float sx = float(std::sqrt(rho2s[i]) / 2048.0);
                        const bool across = (i / 3) % 2 == 0;
                        const float du[4] = {0, sx, 0, sx}, dv[4] = {0, 0, sx * 2048.0f / 3, sx * 2048.0f / 3};
                        for (int k = 0; k < 4; ++k)
                            u.push_back(across ? du[k] : dv[k] / 2048.0f),
                                v.push_back(across ? dv[k] / 2048.0f : du[k] * 2048.0f);
                    }
                    while (u.size() % kSpan) u.push_back(0.0f), v.push_back(0.0f);
                    testutil::forEachSimdLevel([&](SimdLevel simd) {
                        const auto kernel = fastpath::samplerKernels(simd).chooseQuadLevels;
                        for (size_t first = 0; first < u.size(); first += kSpan) {
                            double rho2[kSpan / 4];
                            int32_t l0[kSpan / 4], l1[kSpan / 4], slots[kSpan / 4], mipW[kSpan / 4], linear[kSpan / 4];
                            const int done =
                                kernel(run, kSpan, u.data() + first, v.data() + first, rho2, l0, l1, slots, mipW, linear);
                            CHECK(done == (simd == SimdLevel::Baseline ? 0 : 16));
                            for (int k = 0; k < done; ++k) {
                                const size_t i = first + size_t(4 * k);
                                const float tl[3] = {u[i], v[i], 0}, tr[3] = {u[i + 1], v[i + 1], 0},
                                            bl[3] = {u[i + 2], v[i + 2], 0};
                                const LevelChoice want = quadLevel(*tex, st, tl, tr, bl, true, false);
                                LevelChoice got;
                                if (slots[k] == 0) {
                                    ++leftToChoose;
                                    got = chooseLevel(*tex, st, rho2[k], rho2[k], true, false);
                                } else {
                                    ++decided;
                                    got.level0 = l0[k], got.level1 = l1[k], got.slots = slots[k];
                                    got.linear = linear[k] != 0, got.mipW = mipW[k], got.mipF = float(mipW[k]) / 256.0f;
                                }
                                if (!(got == want) && bad++ < 5)
                                    FAIL_CHECK("kernel at " << simdLevelName(simd) << ", quad " << i << " levels "
                                                            << levels << " slots " << slots[k] << ": level "
                                                            << got.level0 << "/" << got.level1 << " w " << got.mipW
                                                            << ", want " << want.level0 << "/" << want.level1
                                                            << " slots " << want.slots << " w " << want.mipW);
                            }
                        }
                    });
                }
    CHECK(bad == 0);
    // Both kinds of quad occur: the random ones decided by the kernel (at the Avx2 level), those
    // at the edges (and every one at the Baseline level) left to chooseLevel.
    CHECK(decided > 0);
    CHECK(leftToChoose > 0);
}

TEST_CASE("sampler: unbound stages, output spans, fetch counts", "[sampler]") {
    TextureSampler s;
    CHECK_FALSE(s.hasTexture(0));
    CHECK_FALSE(s.bind(8, nullptr));
    CHECK_FALSE(s.setSamplerState(-1, SamplerState{}));
    Result r = run(s, Precision::Fx12, {0.5f}, {0.5f});
    CHECK(G{r.g[0][0], r.g[1][0], r.g[2][0], r.g[3][0]} == G{0, 0, 0, 4080});
    r = run(s, Precision::Float, {0.5f}, {0.5f}, {}, false, 9);  // out-of-range stage
    CHECK(r.f[3][0] == 1.0f);

    s.bind(0, build(TexFormat::A8R8G8B8, 1, 1, {0xff102030}));
    CHECK(s.hasTexture(0));
    // Only some outputs requested: the others stay untouched.
    float u[1] = {0.5f}, v[1] = {0.5f};
    int32_t redOut[1] = {-1};
    SampleRequest req;
    req.count = 1;
    req.u = u, req.v = v;
    SampleResult out;
    out.grid[0] = redOut;
    s.sample(req, out);
    CHECK(redOut[0] == 0x10);
    uint64_t before = s.texelsFetched();
    run(s, Precision::Fx8, std::vector<float>(10, 0.5f), std::vector<float>(10, 0.5f));
    CHECK(s.texelsFetched() - before == 10);  // point: one texel per lane
    s.setSamplerState(0, state(Filter::Linear, TextureAddress::Wrap));
    before = s.texelsFetched();
    run(s, Precision::Fx8, std::vector<float>(10, 0.5f), std::vector<float>(10, 0.5f));
    CHECK(s.texelsFetched() - before == 40);
}

TEST_CASE("sampler: the 8-bit fast path equals the general path", "[sampler]") {
    std::mt19937 rng(1234);
    // 5x3 takes the modulo wrap, 4x4 the power-of-two mask.
    for (uint32_t size : {5u, 4u}) {
        const uint32_t w = size, h = size == 5 ? 3 : 4;
        TextureDesc d = makeDesc(TexFormat::A8R8G8B8, w, h, 0, {});
        for (uint32_t i = 0; i < w * h; ++i) d.data[0].texels.push_back(word(rng()));
        auto tex = build(d);
        std::uniform_real_distribution<float> coord(-2.0f, 3.0f);
        std::uniform_int_distribution<int> grid(-2048, 3072);
        std::vector<float> u(kMaxSpan), v(kMaxSpan);
        for (int i = 0; i < kMaxSpan; ++i) {
            if (i % 2) {
                u[size_t(i)] = coord(rng), v[size_t(i)] = coord(rng);
            } else {  // multiples of 1/1024: exact half-way weights and f*256 rounding to 256
                u[size_t(i)] = float(grid(rng)) / 1024, v[size_t(i)] = float(grid(rng)) / 1024;
            }
        }
        u[0] = 0.5f / float(w), v[0] = 0.5f / float(h);  // exact centres
        u[2] = std::nanf(""), v[4] = std::numeric_limits<float>::infinity(), u[6] = -1e30f;  // the slow lane path
        for (TextureAddress mu : {TextureAddress::Clamp, TextureAddress::Wrap})
            for (TextureAddress mv : {TextureAddress::Clamp, TextureAddress::Wrap})
                for (Precision p : {Precision::Fx8, Precision::Fx12}) {
                    TextureSampler fast, general;
                    general.setFastPath(false);
                    SamplerState st = state(Filter::Linear, mu);
                    st.addressV = mv;
                    for (TextureSampler* s : {&fast, &general}) {
                        s->bind(0, tex);
                        s->setSamplerState(0, st);
                    }
                    Result a = run(fast, p, u, v), b = run(general, p, u, v);
                    for (int c = 0; c < 4; ++c) CHECK(a.g[size_t(c)] == b.g[size_t(c)]);
                }
    }
}

TEST_CASE("sampler: the 8-bit fast path equals the general path for scattered lanes, every address mode and level",
          "[sampler]") {
    // Lanes that are neither one row in order nor screen-aligned quads (a rotated or perspective
    // mapping, a dependent read): the gathering kernels, eight lanes a step and the rest one by
    // one, border lanes among them.
    std::mt19937 rng(20261129);
    for (const auto& [w, h] : {std::pair<uint32_t, uint32_t>{37, 23}, {64, 64}, {1, 9}}) {
        TextureDesc d = makeDesc(TexFormat::A8R8G8B8, w, h, 0, {});
        for (uint32_t i = 0; i < w * h; ++i) d.data[0].texels.push_back(word(rng()));
        auto tex = build(d);
        std::uniform_real_distribution<float> coord(-1.5f, 2.5f);
        for (int count : {kMaxSpan, 1, 7, 8, 13, 100}) {
            std::vector<float> u(static_cast<size_t>(count)), v(static_cast<size_t>(count));
            for (int i = 0; i < count; ++i) {
                // A rotated row: both coordinates move with the lane, with jitter.
                u[size_t(i)] = 0.3f + 0.031f * float(i) + (i % 3 ? 0.0f : coord(rng) * 0.01f);
                v[size_t(i)] = 0.2f + 0.017f * float(i) - (i % 5 ? 0.0f : coord(rng));
                if (i % 11 == 4) u[size_t(i)] = coord(rng), v[size_t(i)] = coord(rng);
                if (i % 16 == 9) u[size_t(i)] = float(int(rng() % 4096) - 1024) / 1024.0f;  // exact half-way weights
            }
            for (TextureAddress mu : {TextureAddress::Clamp, TextureAddress::Wrap, TextureAddress::Mirror,
                                      TextureAddress::Border, TextureAddress::MirrorOnce})
                for (TextureAddress mv : {TextureAddress::Clamp, TextureAddress::Border, TextureAddress::Wrap})
                    for (Filter f : {Filter::Linear, Filter::Point})
                        for (Precision p : {Precision::Fx8, Precision::Fx12}) {
                            INFO(w << "x" << h << " count " << count << " modes " << int(mu) << "," << int(mv)
                                   << " filter " << int(f) << " precision " << int(p));
                            SamplerState st = state(f, mu);
                            st.addressV = mv;
                            st.border = {0.2f, 0.4f, 0.6f, 0.8f};
                            TextureSampler general;
                            general.setFastPath(false);
                            general.bind(0, tex);
                            general.setSamplerState(0, st);
                            const Result b = run(general, p, u, v);
                            testutil::forEachSimdLevel([&](ps11::SimdLevel) {
                                TextureSampler fast;
                                fast.bind(0, tex);
                                fast.setSamplerState(0, st);
                                const Result a = run(fast, p, u, v);
                                for (int c = 0; c < 4; ++c) CHECK(a.g[size_t(c)] == b.g[size_t(c)]);
                            });
                        }
        }
    }
}

TEST_CASE("sampler: the float profiles' 8-bit fast path equals the general path bit for bit", "[sampler]") {
    // Lanes as a dependent read puts them (scattered, some far outside, NaN, infinite, half-way
    // between texels), every address mode, point and bilinear, float with and without the class's
    // 8-bit weights and ideal, a border colour inside [0, 1] and one outside; spans of 1..kMaxSpan
    // (the gathering kernel's eight lanes a step and its tail), at every SIMD level. Half the
    // spans are rows in order (a plain read's: consecutive columns, one row pair), which the
    // kernel loads instead of gathering where eight columns lie inside the texture.
    std::mt19937 rng(20261130);
    for (const auto& [w, h] : {std::pair<uint32_t, uint32_t>{37, 23}, {64, 32}, {1, 5}}) {
        TextureDesc d = makeDesc(TexFormat::A8R8G8B8, w, h, 0, {});
        for (uint32_t i = 0; i < w * h; ++i) d.data[0].texels.push_back(word(rng()));
        auto tex = build(d);
        std::uniform_real_distribution<float> coord(-1.5f, 2.5f);
        for (int count : {kMaxSpan, 1, 7, 8, 13, 100, 24, 40}) {
            for (bool inOrder : {false, true}) {
                std::vector<float> u(static_cast<size_t>(count)), v(static_cast<size_t>(count));
                const float start = coord(rng), row = coord(rng), frac = float(rng() % 256) / 256.0f;
                for (int i = 0; i < count; ++i) {
                    if (inOrder) {
                        u[size_t(i)] = start + (float(i) + frac) / float(w), v[size_t(i)] = row;
                        continue;
                    }
                    u[size_t(i)] = coord(rng), v[size_t(i)] = coord(rng);
                    if (i % 16 == 9) u[size_t(i)] = float(int(rng() % 4096) - 1024) / 1024.0f;  // half-way weights
                    if (i % 16 == 10) v[size_t(i)] = (float(rng() % 64) + 0.5f) / float(h);     // texel centres
                }
                if (count > 20 && !inOrder) {
                    u[3] = std::nanf(""), v[5] = std::numeric_limits<float>::infinity(), u[11] = -1e30f;
                    v[17] = 3e9f;
                }
                for (TextureAddress mu : {TextureAddress::Clamp, TextureAddress::Wrap, TextureAddress::Mirror,
                                          TextureAddress::Border, TextureAddress::MirrorOnce})
                    for (TextureAddress mv : {TextureAddress::Clamp, TextureAddress::Border, TextureAddress::Wrap})
                        for (Filter f : {Filter::Linear, Filter::Point})
                            for (int profile = 0; profile < 3; ++profile) {
                                const Precision p = profile == 2 ? Precision::Ideal : Precision::Float;
                                const int weightBits = profile == 1 ? 8 : 0;
                                SamplerState st = state(f, mu);
                                st.addressV = mv;
                                st.border = (count % 2) ? std::array<float, 4>{0.2f, 0.4f, 0.6f, 0.8f}
                                                        : std::array<float, 4>{0.25f, -1.5f, 3.0f, 0.0f};
                                INFO(w << "x" << h << " count " << count << " modes " << int(mu) << "," << int(mv)
                                       << " filter " << int(f) << " profile " << profile);
                                TextureSampler general;
                                general.setFastPath(false);
                                general.setWeightBits(weightBits);
                                general.bind(0, tex);
                                general.setSamplerState(0, st);
                                const Result b = run(general, p, u, v);
                                testutil::forEachSimdLevel([&](ps11::SimdLevel) {
                                    for (bool quads : {false, true}) {
                                        TextureSampler fast;
                                        fast.setWeightBits(weightBits);
                                        fast.bind(0, tex);
                                        fast.setSamplerState(0, st);
                                        const Result a = run(fast, p, u, v, {}, quads && count % 4 == 0);
                                        CHECK(fast.fastLanes() == uint64_t(count));
                                        for (int c = 0; c < 4; ++c)
                                            CHECK(std::memcmp(a.f[size_t(c)].data(), b.f[size_t(c)].data(),
                                                              sizeof(float) * size_t(count)) == 0);
                                    }
                                });
                            }
            }
        }
    }
}

TEST_CASE("sampler: lanes at levels given per lane, and blends of two levels, equal the general path's quads",
          "[sampler]") {
    // SampleRequest::levels (what the device's row paths hand over, each quad's quadLevel kept for
    // its two rows): random quads of coordinates over a 64x32 chain of random texels, MIP filter
    // POINT and LINEAR, MIN != MAG, in fx8, fx12, float (with and without 8-bit weights) and ideal,
    // through the fast path (at every SIMD level: its one- and two-level kernels, set by set where
    // quads change level) and the general one. Each quad's lanes sampled
    // with their quad's choice and no quads, and the quads through the fast path, must give the
    // bytes or floats the general path gives the quads.
    std::mt19937 rng(20261203);
    TextureDesc d = makeDesc(TexFormat::A8R8G8B8, 64, 32, 0, {});
    for (uint32_t i = 0; i < 64 * 32; ++i) d.data[0].texels.push_back(word(rng()));
    d.levels = {0, 1};  // the whole chain, generated
    auto tex = build(d);
    REQUIRE(tex->levelCount() == 7);
    std::uniform_real_distribution<float> at(-0.5f, 1.5f), step(-0.2f, 0.2f);
    const int quads = 64;
    std::vector<float> u(4 * quads), v(4 * quads);
    for (int q = 0; q < quads; ++q) {
        // A quad at (u0, v0) whose x and y steps reach anything from magnified to level 6.
        const float u0 = at(rng), v0 = at(rng), dux = step(rng), dvx = step(rng) * 0.5f, duy = step(rng) * 0.5f,
                    dvy = step(rng);
        for (int k = 0; k < 4; ++k) {
            const float x = float(k & 1), y = float(k >> 1);
            u[size_t(4 * q + k)] = u0 + x * dux + y * duy;
            v[size_t(4 * q + k)] = v0 + x * dvx + y * dvy;
        }
    }
    int blends = 0;
    for (Filter mip : {Filter::Point, Filter::Linear})
        for (Filter minf : {Filter::Linear, Filter::Point})
            for (int config = 0; config < 5; ++config)  // fx8, fx12, float, ideal, float with 8-bit weights
                for (bool fastPath : {true, false}) {
                    const Precision p = std::array<Precision, 5>{Precision::Fx8, Precision::Fx12, Precision::Float,
                                                                 Precision::Ideal, Precision::Float}[size_t(config)];
                    const int weightBits = config == 4 ? 8 : 0;
                    SamplerState st = state(Filter::Linear, TextureAddress::Wrap, mip);
                    st.minFilter = minf;
                    const bool fixed = isFixedPoint(p);
                    std::vector<LevelChoice> levels(u.size());
                    for (int q = 0; q < quads; ++q) {
                        const size_t i = size_t(4 * q);
                        const float tl[3] = {u[i], v[i], 0}, tr[3] = {u[i + 1], v[i + 1], 0},
                                    bl[3] = {u[i + 2], v[i + 2], 0};
                        const LevelChoice c = quadLevel(*tex, st, tl, tr, bl, fixed, weightBits == 8);
                        blends += c.slots == 2;
                        for (int k = 0; k < 4; ++k) levels[i + size_t(k)] = c;
                    }
                    INFO("mip " << int(mip) << " min " << int(minf) << " precision " << int(p) << " weight bits "
                                << weightBits << " fast " << fastPath);
                    TextureSampler general;
                    general.setFastPath(false);
                    general.setWeightBits(weightBits);
                    general.bind(0, tex);
                    general.setSamplerState(0, st);
                    const Result a = run(general, p, u, v, {}, true);
                    testutil::forEachSimdLevel([&](ps11::SimdLevel) {
                        TextureSampler s;
                        s.setFastPath(fastPath);
                        s.setWeightBits(weightBits);
                        s.bind(0, tex);
                        s.setSamplerState(0, st);
                        // The grid integers (fx) or the floats bit for bit.
                        auto same = [&](const Result& b) {
                            for (int c = 0; c < 4; ++c) {
                                if (fixed) CHECK(b.g[size_t(c)] == a.g[size_t(c)]);
                                for (size_t i = 0; !fixed && i < u.size(); ++i)
                                    CHECK(std::bit_cast<uint32_t>(b.f[size_t(c)][i]) ==
                                          std::bit_cast<uint32_t>(a.f[size_t(c)][i]));
                            }
                        };
                        same(run(s, p, u, v, {}, true));
                        same(run(s, p, u, v, {}, false, 0, levels.data()));
                        // Blends of levels that are not neighbours (a caller's choice chooseLevel
                        // never makes; the fast path then groups lanes by searching their keys): as
                        // the general path samples the same choices.
                        if (mip == Filter::Linear) {
                            std::vector<LevelChoice> far = levels;
                            for (size_t i = 0; i < far.size(); i += 8)
                                if (far[i].slots == 2 && far[i].level1 + 1 < tex->levelCount()) ++far[i].level1;
                            const Result want = run(general, p, u, v, {}, false, 0, far.data());
                            auto b = run(s, p, u, v, {}, false, 0, far.data());
                            for (int c = 0; c < 4; ++c) {
                                if (fixed) CHECK(b.g[size_t(c)] == want.g[size_t(c)]);
                                for (size_t i = 0; !fixed && i < u.size(); ++i)
                                    CHECK(std::bit_cast<uint32_t>(b.f[size_t(c)][i]) ==
                                          std::bit_cast<uint32_t>(want.f[size_t(c)][i]));
                            }
                        }
                    });
                }
    CHECK(blends > 0);  // some quads blend two levels
}

TEST_CASE("sampler: floatAxisTaps gives the same pairs and weights at every SIMD level", "[sampler]") {
    // The float row paths' axis rule (tabulated columns, per-pixel taps): the Avx2 kernel against
    // the Baseline's lane-by-lane rule, over coordinates near texel edges, far outside, huge,
    // infinite and NaN, in every address mode.
    std::mt19937 rng(20261129);
    std::uniform_real_distribution<float> coord(-3.0f, 4.0f);
    std::vector<float> c(301);
    for (size_t i = 0; i < c.size(); ++i) c[i] = coord(rng);
    for (size_t i = 0; i < c.size(); i += 7) c[i] = float(int(rng() % 8192) - 2048) / 1024.0f;  // exact halves
    c[3] = std::nanf(""), c[10] = std::numeric_limits<float>::infinity(), c[11] = -1e30f, c[12] = 3e9f;
    c[13] = -0.0f, c[14] = 1e-40f;
    for (uint32_t n : {1u, 5u, 37u, 1024u, 16384u})
        for (TextureAddress mode : {TextureAddress::Wrap, TextureAddress::Mirror, TextureAddress::Clamp,
                                    TextureAddress::Border, TextureAddress::MirrorOnce})
            for (bool linear : {false, true})
                for (bool weights8 : {false, true}) {
                    INFO("n " << n << " mode " << int(mode) << " linear " << linear << " weights8 " << weights8);
                    std::vector<int32_t> i0[2], i1[2];
                    std::vector<float> f[2];
                    int k = 0;
                    testutil::forEachSimdLevel([&](ps11::SimdLevel) {
                        const int at = std::min(k++, 1);
                        i0[at].assign(c.size(), -7), i1[at].assign(c.size(), -7), f[at].assign(c.size(), -7.0f);
                        floatAxisTaps(mode, linear, weights8, int(c.size()), c.data(), n, i0[at].data(), i1[at].data(),
                                      f[at].data());
                    });
                    for (size_t i = 0; i < c.size(); ++i) {
                        CHECK(i0[0][i] >= -1);
                        CHECK(i0[0][i] < int32_t(n));
                    }
                    if (k < 2) continue;  // one level on this CPU
                    CHECK(i0[0] == i0[1]);
                    CHECK(i1[0] == i1[1]);
                    for (size_t i = 0; i < c.size(); ++i)
                        CHECK(std::bit_cast<uint32_t>(f[0][i]) == std::bit_cast<uint32_t>(f[1][i]));
                }
}

TEST_CASE("sampler: says when every fx lookup lies in [0, G] (8-bit texels, a border of bytes)", "[sampler]") {
    // SampleResult::unitRange lets the executor skip the ±MaxValue clamp of the result.
    const auto unit = [](TextureSampler& s, Precision p) {
        const std::vector<float> u{0.1f, 0.7f, -0.4f, 1.6f}, v{0.2f, 0.9f, 0.5f, -0.3f};
        int32_t g[4][4];
        SampleRequest req;
        req.count = 4, req.dims = 2, req.u = u.data(), req.v = v.data(), req.precision = p;
        SampleResult out;
        for (int c = 0; c < 4; ++c) out.grid[c] = g[c];
        out.unitRange = true;  // a stale flag is cleared
        s.sample(req, out);
        for (int c = 0; c < 4; ++c)
            for (int i = 0; i < 4 && out.unitRange; ++i) CHECK((g[c][i] >= 0 && g[c][i] <= gridScale(p)));
        return out.unitRange;
    };
    for (Precision p : {Precision::Fx8, Precision::Fx12}) {
        INFO(precisionName(p));
        TextureSampler s;
        s.bind(0, build(TexFormat::A8R8G8B8, 2, 2, {0xffffffff, 0x00000000, 0x80ff0010, 0x7f00ff01}));
        s.setSamplerState(0, state(Filter::Linear, TextureAddress::Wrap));
        CHECK(unit(s, p));
        SamplerState border = state(Filter::Linear, TextureAddress::Border);
        border.border = {1, 0.2f, 0, 1};  // 0.2 = 51/255: a byte on both grids
        s.setSamplerState(0, border);
        CHECK(unit(s, p));
        s.bind(0, build(TexFormat::V8U8, 2, 2, {0x817f, 0x8040, 0x0000, 0x7f7f}));
        s.setSamplerState(0, state(Filter::Linear, TextureAddress::Wrap));
        CHECK_FALSE(unit(s, p));  // signed texels
    }
}

TEST_CASE("texture: an 8-bit texel's float is float(b) / 255 rounded once", "[texture]") {
    // The row paths decode 8-bit texel rows with a float division per channel instead of the
    // table (emu/aligned_float.cpp, the output merger's blends): both must give the same floats.
    const float* table = ps11::Texture::unorm8Values();
    for (int b = 0; b < 256; ++b) {
        volatile float divided = float(b) / 255.0f;
        INFO("byte " << b);
        CHECK(table[b] == divided);
    }
}
