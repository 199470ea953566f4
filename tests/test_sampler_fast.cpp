// The fast sampler kernels and the direct texture hand-over against their references:
// - Texture::fromLevels (D3D memory layout) builds the same texture as textureFromDesc from the
//   same texel words / floats, for every format, texel by texel;
// - TextureSampler with the fast path, at every SIMD level this CPU runs (ps11/simd_dispatch.h),
//   answers bit-identically to TextureSampler(false), the reference path, over random and adversarial
//   coordinates, every address mode pair, border colours, filters, mips with quads and span
//   lengths 1..256. The reference's own values are checked by hand in test_texture_sampler.cpp.
#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "emu/device.h"
#include "emu/format.h"
#include "ps11/testfile.h"
#include "ps11/testfile_textures.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"
#include "simd_levels.h"

using namespace ps11;

namespace {

constexpr TexFormat kAllFormats[] = {
    TexFormat::A8R8G8B8,      TexFormat::X8R8G8B8,      TexFormat::A8,       TexFormat::L8,       TexFormat::A8L8,
    TexFormat::V8U8,          TexFormat::L6V5U5,        TexFormat::X8L8V8U8, TexFormat::Q8W8V8U8, TexFormat::V16U16,
    TexFormat::A16B16G16R16F, TexFormat::A32B32G32R32F, TexFormat::R32F};
constexpr TexFormat kUnorm8Formats[] = {TexFormat::A8R8G8B8, TexFormat::X8R8G8B8, TexFormat::A8, TexFormat::L8,
                                        TexFormat::A8L8};
constexpr TextureAddress kModes[] = {TextureAddress::Wrap, TextureAddress::Mirror, TextureAddress::Clamp,
                                     TextureAddress::Border, TextureAddress::MirrorOnce};

uint32_t extent(uint32_t size, uint32_t k) { return std::max<uint32_t>(1, size >> k); }

// Levels in D3D's memory layout with padded pitches, filled with random bytes.
struct D3DLevels {
    std::vector<std::vector<uint8_t>> bytes;
    std::vector<TextureLevelBytes> levels;
};

D3DLevels randomLevels(std::mt19937& rng, TexFormat f, uint32_t w, uint32_t h, uint32_t d, uint32_t count,
                       bool finiteFloats) {
    D3DLevels out;
    const uint32_t bpt = bytesPerTexel(f);
    out.bytes.resize(count);
    for (uint32_t k = 0; k < count; ++k) {
        TextureLevelBytes l;
        l.width = extent(w, k), l.height = extent(h, k), l.depth = extent(d, k);
        l.rowPitch = (l.width * bpt + 3u) / 4u * 4u + 4u * (k % 2);  // some rows padded beyond D3D's minimum
        l.slicePitch = l.rowPitch * l.height + 8;
        std::vector<uint8_t>& b = out.bytes[k];
        b.resize(l.slicePitch * l.depth);
        for (uint8_t& x : b) x = uint8_t(rng());
        if (finiteFloats && isFloatFormat(f)) {
            // Mostly ordinary values; random bits would be NaN/huge too often to say much.
            std::uniform_real_distribution<float> val(-3.0f, 3.0f);
            for (uint32_t z = 0; z < l.depth; ++z)
                for (uint32_t y = 0; y < l.height; ++y)
                    for (uint32_t x = 0; x < l.width; ++x) {
                        uint8_t* p = b.data() + z * l.slicePitch + y * l.rowPitch + x * bpt;
                        for (uint32_t c = 0; c < (f == TexFormat::R32F ? 1u : 4u); ++c) {
                            const float v = val(rng);
                            if (f == TexFormat::A16B16G16R16F) {
                                const uint16_t hb = emu::floatToHalf(v);
                                std::memcpy(p + 2 * c, &hb, 2);
                            } else {
                                std::memcpy(p + 4 * c, &v, 4);
                            }
                        }
                    }
        }
        l.data = b.data();
        out.levels.push_back(l);
    }
    return out;
}

// The same texels as a .ps11test description: packed words (little endian) or floats.
TextureDesc descOf(TexFormat f, bool volume, const D3DLevels& L) {
    TextureDesc desc;
    desc.format = {f, 1};
    desc.width = L.levels[0].width, desc.height = L.levels[0].height, desc.depth = volume ? L.levels[0].depth : 0;
    desc.sizeLine = 1;
    desc.levels = {uint32_t(L.levels.size()), 1};
    const uint32_t bpt = bytesPerTexel(f);
    for (size_t k = 0; k < L.levels.size(); ++k) {
        const TextureLevelBytes& l = L.levels[k];
        TextureLevel tl;
        tl.level = uint32_t(k);
        tl.width = l.width, tl.height = l.height, tl.depth = l.depth;
        for (uint32_t z = 0; z < l.depth; ++z)
            for (uint32_t y = 0; y < l.height; ++y)
                for (uint32_t x = 0; x < l.width; ++x) {
                    const uint8_t* p = l.data + z * l.slicePitch + y * l.rowPitch + x * bpt;
                    Texel t;
                    if (f == TexFormat::R32F) {
                        std::memcpy(&t.value[0], p, 4);
                        t.count = 1;
                    } else if (f == TexFormat::A32B32G32R32F) {
                        std::memcpy(t.value.data(), p, 16);
                        t.count = 4;
                    } else if (f == TexFormat::A16B16G16R16F) {
                        for (int c = 0; c < 4; ++c)
                            t.value[size_t(c)] = emu::halfToFloat(uint16_t(p[2 * c] | p[2 * c + 1] << 8));
                        t.count = 4;
                    } else {
                        for (uint32_t i = 0; i < bpt; ++i) t.bits |= uint32_t(p[i]) << (8 * i);
                    }
                    tl.texels.push_back(t);
                }
        desc.data.push_back(tl);
    }
    return desc;
}

bool sameFloat(float a, float b) {
    return (std::isnan(a) && std::isnan(b)) || std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b);
}

void checkSameTexture(const Texture& a, const Texture& b) {
    REQUIRE(a.format() == b.format());
    REQUIRE(a.isVolume() == b.isVolume());
    REQUIRE(a.storage() == b.storage());
    REQUIRE(a.levelCount() == b.levelCount());
    REQUIRE(a.texelCount() == b.texelCount());
    int mismatches = 0;
    for (int k = 0; k < a.levelCount(); ++k) {
        const TextureLevelInfo& la = a.level(k);
        const TextureLevelInfo& lb = b.level(k);
        REQUIRE((la.width == lb.width && la.height == lb.height && la.depth == lb.depth && la.offset == lb.offset));
        for (uint32_t z = 0; z < la.depth; ++z)
            for (uint32_t y = 0; y < la.height; ++y)
                for (uint32_t x = 0; x < la.width; ++x) {
                    const Vec4 va = a.texelValue(k, x, y, z), vb = b.texelValue(k, x, y, z);
                    for (size_t c = 0; c < 4; ++c) mismatches += !sameFloat(va[c], vb[c]);
                    mismatches += a.texelGrid(k, x, y, z, Precision::Fx8) != b.texelGrid(k, x, y, z, Precision::Fx8);
                    mismatches += a.texelGrid(k, x, y, z, Precision::Fx12) != b.texelGrid(k, x, y, z, Precision::Fx12);
                }
    }
    // The raw arrays the sampler reads must agree too (Unorm8: the b g r a bytes).
    if (a.storage() == TexelStorage::Unorm8) mismatches += std::memcmp(a.unorm8(), b.unorm8(), a.texelCount() * 4) != 0;
    CHECK(mismatches == 0);
}

SamplerState makeState(Filter minF, Filter magF, Filter mip, TextureAddress u, TextureAddress v, Vec4 border) {
    SamplerState s;
    s.minFilter = minF, s.magFilter = magF, s.mipFilter = mip;
    s.addressU = u, s.addressV = v, s.addressW = TextureAddress::Wrap;
    s.border = border;
    return s;
}

// Random coordinates for one axis of n texels with the cases that matter: ordinary, negative,
// far outside, exactly on texel centres, half-way weights (f*256 = k + 1/2), f*256 rounding up
// to 256, point ties (u*n integer), huge, infinite and NaN.
float nastyCoord(std::mt19937& rng, uint32_t n) {
    const int kind = int(rng() % 12);
    std::uniform_real_distribution<float> unit(-0.25f, 1.25f);
    std::uniform_int_distribution<int> texel(-int(n) - 3, 2 * int(n) + 3);
    switch (kind) {
        case 0:
        case 1:
        case 2:
            return unit(rng);
        case 3:
            return std::uniform_real_distribution<float>(-50.0f, 50.0f)(rng);
        case 4:
            return (float(texel(rng)) + 0.5f) / float(n);  // a texel centre
        case 5:                                            // half-way weight: x*256 = m + 1/2 with x = u*n - 1/2
            return float((double(texel(rng)) * 256.0 + 128.0 + double(rng() % 256) + 0.5) / (256.0 * n));
        case 6:  // weight 255.5..256: f*256 rounds to 256
            return float((double(texel(rng)) + 0.5 + 255.75 / 256.0) / n);
        case 7:
            return float(texel(rng)) / float(n);  // point tie: u*n an integer
        case 8:
            return std::uniform_real_distribution<float>(-1e7f, 1e7f)(rng);  // beyond the integer fast range
        case 9: {
            const float special[] = {std::numeric_limits<float>::infinity(),
                                     -std::numeric_limits<float>::infinity(),
                                     std::nanf(""),
                                     1e30f,
                                     -1e30f,
                                     0.0f,
                                     -0.0f,
                                     4194304.0f,
                                     -8388608.5f};
            return special[rng() % 9];
        }
        case 10:  // exact multiples of 1/(512 n) around the texture
            return float(double(std::uniform_int_distribution<int>(-1024 * int(n), 1024 * int(n))(rng)) / (512.0 * n));
        default:
            return std::uniform_real_distribution<float>(-3.0f, 4.0f)(rng);
    }
}

struct Out {
    std::array<std::vector<int32_t>, 4> g;
    std::array<std::vector<float>, 4> f;
};

Out sampleSpan(TextureSampler& s, Precision p, const float* u, const float* v, int count, bool quads) {
    Out o;
    SampleRequest req;
    req.count = count;
    req.quads = quads;
    req.dims = 2;
    req.u = u, req.v = v;
    req.precision = p;
    SampleResult r;
    for (int c = 0; c < 4; ++c) {
        o.g[size_t(c)].assign(size_t(count), -77777);
        o.f[size_t(c)].assign(size_t(count), -7.0f);
        r.grid[c] = o.g[size_t(c)].data();
        r.value[c] = o.f[size_t(c)].data();
    }
    s.sample(req, r);
    return o;
}

struct Pair {
    TextureSampler fast{true}, ref{false};
    void set(const std::shared_ptr<const Texture>& t, const SamplerState& st) {
        for (TextureSampler* s : {&fast, &ref}) {
            s->bind(0, t);
            s->setSamplerState(0, st);
        }
    }
};

// Compares fast and reference over one span; returns the number of differing outputs and
// checks the fetch statistics agree.
int compareSpan(Pair& pr, Precision p, const float* u, const float* v, int count, bool quads) {
    const uint64_t fetchedFast = pr.fast.texelsFetched(), fetchedRef = pr.ref.texelsFetched();
    const Out a = sampleSpan(pr.fast, p, u, v, count, quads);
    const Out b = sampleSpan(pr.ref, p, u, v, count, quads);
    int bad = 0;
    for (size_t c = 0; c < 4; ++c) {
        bad += a.g[c] != b.g[c];
        for (int i = 0; i < count; ++i) bad += !sameFloat(a.f[c][size_t(i)], b.f[c][size_t(i)]);
    }
    bad += (pr.fast.texelsFetched() - fetchedFast) != (pr.ref.texelsFetched() - fetchedRef);
    return bad;
}

std::shared_ptr<const Texture> randomTexture(std::mt19937& rng, TexFormat f, uint32_t w, uint32_t h, uint32_t levels) {
    D3DLevels L = randomLevels(rng, f, w, h, 1, levels, true);
    std::string error;
    std::optional<Texture> t = Texture::fromLevels(f, false, L.levels.data(), L.levels.size(), SignedDecode::Snorm, error);
    INFO(error);
    REQUIRE(t);
    return std::make_shared<const Texture>(std::move(*t));
}

}  // namespace

TEST_CASE("texture: fromLevels equals textureFromDesc for every format", "[sampler][fast]") {
    std::mt19937 rng(77);
    const struct {
        uint32_t w, h, d;
        bool volume;
    } shapes[] = {{7, 5, 1, false}, {16, 8, 1, false}, {1, 9, 1, false}, {5, 3, 4, true}, {4, 4, 2, true}};
    for (TexFormat f : kAllFormats)
        for (const auto& s : shapes)
            for (bool finite : {true, false}) {
                INFO(texFormatName(f) << " " << s.w << "x" << s.h << "x" << s.d << (finite ? "" : " random bits"));
                const uint32_t levels = fullMipCount(s.w, s.h, s.volume ? s.d : 1);
                D3DLevels L = randomLevels(rng, f, s.w, s.h, s.volume ? s.d : 1, levels, finite);
                std::string e1, e2;
                std::optional<Texture> a = Texture::fromLevels(f, s.volume, L.levels.data(), L.levels.size(), SignedDecode::Snorm, e1);
                std::optional<Texture> b = textureFromDesc(descOf(f, s.volume, L), SignedDecode::Snorm, e2);
                INFO(e1 << " / " << e2);
                REQUIRE(a);
                REQUIRE(b);
                checkSameTexture(*a, *b);
            }
}

TEST_CASE("texture: the device hands every format over as textureFromDesc builds it", "[sampler][fast]") {
    // Through emu::Device: random bytes written with LockRect/LockBox (D3D pitches, odd widths so
    // 1- and 2-byte formats have padded rows), then sampledTexture (makeSampledTexture ->
    // Texture::fromLevels) against textureFromDesc of the same texels.
    using emu::D3D_OK, emu::D3DFORMAT, emu::D3DLOCKED_BOX, emu::D3DLOCKED_RECT, emu::D3DPOOL_MANAGED;
    std::mt19937 rng(31);
    for (TexFormat f : kAllFormats)
        for (bool volume : {false, true}) {
            INFO(texFormatName(f) << (volume ? " volume" : ""));
            emu::Device dev;
            const D3DFORMAT d3d = emu::d3dFormatOf(f);
            const uint32_t w = 7, h = 5, d = volume ? 3 : 1;
            emu::Handle tex{};
            if (volume)
                REQUIRE(dev.CreateVolumeTexture(w, h, d, 0, 0, d3d, D3DPOOL_MANAGED, &tex) == D3D_OK);
            else
                REQUIRE(dev.CreateTexture(w, h, 0, 0, d3d, D3DPOOL_MANAGED, &tex) == D3D_OK);
            const uint32_t levels = dev.GetLevelCount(tex);
            REQUIRE(levels == fullMipCount(w, h, d));
            D3DLevels L;  // the bytes as the device holds them, for the description
            L.bytes.resize(levels);
            for (uint32_t k = 0; k < levels; ++k) {
                TextureLevelBytes l;
                l.width = extent(w, k), l.height = extent(h, k), l.depth = extent(d, k);
                void* bits = nullptr;
                if (volume) {
                    D3DLOCKED_BOX box;
                    REQUIRE(dev.LockBox(tex, k, &box, nullptr, 0) == D3D_OK);
                    l.rowPitch = size_t(box.RowPitch), l.slicePitch = size_t(box.SlicePitch), bits = box.pBits;
                } else {
                    D3DLOCKED_RECT rect;
                    REQUIRE(dev.LockRect(tex, k, &rect, nullptr, 0) == D3D_OK);
                    l.rowPitch = size_t(rect.Pitch), l.slicePitch = l.rowPitch * l.height, bits = rect.pBits;
                }
                D3DLevels one = randomLevels(rng, f, l.width, l.height, l.depth, 1, true);
                std::vector<uint8_t>& b = L.bytes[k];
                b.assign(l.slicePitch * l.depth, 0);
                const uint32_t row = l.width * bytesPerTexel(f);
                for (uint32_t z = 0; z < l.depth; ++z)
                    for (uint32_t y = 0; y < l.height; ++y) {
                        const uint8_t* src =
                            one.levels[0].data + z * one.levels[0].slicePitch + y * one.levels[0].rowPitch;
                        std::memcpy(b.data() + z * l.slicePitch + y * l.rowPitch, src, row);
                        std::memcpy(static_cast<uint8_t*>(bits) + z * l.slicePitch + y * l.rowPitch, src, row);
                    }
                REQUIRE((volume ? dev.UnlockBox(tex, k) : dev.UnlockRect(tex, k)) == D3D_OK);
                l.data = b.data();
                L.levels.push_back(l);
            }
            std::shared_ptr<const Texture> got = dev.sampledTexture(tex);
            REQUIRE(got);
            std::string error;
            std::optional<Texture> want = textureFromDesc(descOf(f, volume, L), SignedDecode::Snorm, error);
            INFO(error);
            REQUIRE(want);
            checkSameTexture(*got, *want);
        }
}

TEST_CASE("texture: fromLevels stores A8R8G8B8 as D3D's bytes and X8 alpha as 255", "[sampler][fast]") {
    // Texel word 0x80402010 is bytes 10 20 40 80 (B G R A) in memory; fx8 reads r g b a = 0x40 0x20 0x10 0x80.
    const uint8_t bytes[8] = {0x10, 0x20, 0x40, 0x80, 0x01, 0x02, 0x03, 0x04};
    TextureLevelBytes l{2, 1, 1, bytes, 8, 8};
    std::string error;
    std::optional<Texture> t = Texture::fromLevels(TexFormat::A8R8G8B8, false, &l, 1, SignedDecode::Snorm, error);
    REQUIRE(t);
    CHECK(std::memcmp(t->unorm8(), bytes, 8) == 0);
    CHECK(t->texelGrid(0, 0, 0, 0, Precision::Fx8) == std::array<int32_t, 4>{0x40, 0x20, 0x10, 0x80});
    CHECK(t->texelGrid(0, 1, 0, 0, Precision::Fx12) ==
          std::array<int32_t, 4>{0x03 * 16, 0x02 * 16, 0x01 * 16, 0x04 * 16});
    std::optional<Texture> x = Texture::fromLevels(TexFormat::X8R8G8B8, false, &l, 1, SignedDecode::Snorm, error);
    REQUIRE(x);
    CHECK(x->texelGrid(0, 0, 0, 0, Precision::Fx8) == std::array<int32_t, 4>{0x40, 0x20, 0x10, 255});
}

TEST_CASE("texture: fromLevels refuses bad levels with a message", "[sampler][fast]") {
    std::vector<uint8_t> buf(64 * 64 * 4);
    std::string error;
    TextureLevelBytes l{8, 8, 1, buf.data(), 32, 256};
    CHECK_FALSE(Texture::fromLevels(TexFormat::A8R8G8B8, false, &l, 0, SignedDecode::Snorm, error));
    CHECK(error == "texture has no levels");
    TextureLevelBytes two[2] = {l, {8, 8, 1, buf.data(), 32, 256}};  // level 1 must be 4x4
    CHECK_FALSE(Texture::fromLevels(TexFormat::A8R8G8B8, false, two, 2, SignedDecode::Snorm, error));
    CHECK(error == "level 1 is 8x8, expected 4x4");
    TextureLevelBytes narrow{8, 8, 1, buf.data(), 16, 128};  // pitch below 8 * 4 bytes
    CHECK_FALSE(Texture::fromLevels(TexFormat::A8R8G8B8, false, &narrow, 1, SignedDecode::Snorm, error));
    CHECK(error == "level 0 has no data or a pitch smaller than its rows");
    TextureLevelBytes none{8, 8, 1, nullptr, 32, 256};
    CHECK_FALSE(Texture::fromLevels(TexFormat::A8R8G8B8, false, &none, 1, SignedDecode::Snorm, error));
    TextureLevelBytes big{20000, 1, 1, buf.data(), 80000, 80000};
    CHECK_FALSE(Texture::fromLevels(TexFormat::A8R8G8B8, false, &big, 1, SignedDecode::Snorm, error));
    CHECK(error.find("beyond the limits") != std::string::npos);
    std::vector<TextureLevelBytes> many(5, TextureLevelBytes{1, 1, 1, buf.data(), 4, 4});
    many[0] = {4, 4, 1, buf.data(), 16, 64};
    CHECK_FALSE(Texture::fromLevels(TexFormat::A8R8G8B8, false, many.data(), many.size(), SignedDecode::Snorm, error));
    CHECK(error == "levels 5 is more than the texture has (3)");
    // 16384 x 16384 V16U16 needs 2^28 * 64 bytes decoded: refused before anything is allocated.
    TextureLevelBytes huge{16384, 16384, 1, buf.data(), 65536, 65536ull * 16384};
    CHECK_FALSE(Texture::fromLevels(TexFormat::V16U16, false, &huge, 1, SignedDecode::Snorm, error));
    CHECK(error.find("more than the limit of " + std::to_string(ps11::kMaxResourceBytes)) != std::string::npos);
}

TEST_CASE("sampler fast: equals the reference, every format, address mode pair and filter", "[sampler][fast]") {
    std::mt19937 rng(2026);
    const Vec4 borders[] = {{0, 0, 0, 0}, {1, 1, 1, 1}, {0.5f, 0.25f, 1.0f, 0.0f}, {-0.5f, 2.0f, 0.3f, 1.0f}};
    const uint32_t sizes[][2] = {{5, 3}, {16, 16}, {1, 7}, {33, 1}, {2, 2}};
    const Filter filters[] = {Filter::Point, Filter::Linear};
    uint64_t fastLanes = 0;
    int bad = 0;
    testutil::forEachSimdLevel([&](SimdLevel) {
        for (TexFormat f : kAllFormats)
            for (const auto& sz : sizes) {
                auto tex = randomTexture(rng, f, sz[0], sz[1], 1);
                for (TextureAddress mu : kModes)
                    for (TextureAddress mv : kModes)
                        for (Filter flt : filters)
                            for (Precision p : {Precision::Fx8, Precision::Fx12, Precision::Float}) {
                                const Vec4 border = borders[rng() % 4];
                                Pair pr;
                                pr.set(tex, makeState(flt, flt, Filter::None, mu, mv, border));
                                const int count = 1 + int(rng() % kMaxSpan);
                                std::vector<float> u(static_cast<size_t>(count)), v(static_cast<size_t>(count));
                                for (int i = 0; i < count; ++i)
                                    u[size_t(i)] = nastyCoord(rng, sz[0]), v[size_t(i)] = nastyCoord(rng, sz[1]);
                                const int b = compareSpan(pr, p, u.data(), v.data(), count, false);
                                if (b)
                                    INFO(texFormatName(f)
                                         << " " << int(mu) << "/" << int(mv) << " filter " << int(flt));
                                bad += b;
                                fastLanes += pr.fast.fastLanes();
                            }
            }
    });
    CHECK(bad == 0);
    CHECK(fastLanes > 100000);  // the fast kernels did run (not everything fell back)
}

TEST_CASE("sampler fast: every span length 1..256 and every border colour kind", "[sampler][fast]") {
    std::mt19937 rng(99);
    int bad = 0;
    testutil::forEachSimdLevel([&](SimdLevel) {
        for (TexFormat f : kUnorm8Formats) {
            auto tex = randomTexture(rng, f, 1920 / 64, 1080 / 60, 1);  // 30 x 18
            for (int count = 1; count <= kMaxSpan; ++count) {
                const TextureAddress mu = kModes[size_t(count) % 5], mv = kModes[size_t(count / 5) % 5];
                // Border colours exactly on the byte grid (the fast path takes them), half-way between
                // bytes in fx12 (0.5 * 4080 = 2040 = 127.5 * 16: the reference path) and outside [0, 1].
                const Vec4 border = count % 3 == 0   ? Vec4{float(count) / 255.0f, 1.0f, 0.0f, 0.5f}
                                    : count % 3 == 1 ? Vec4{0.5f, 0.5f, 0.5f, 0.5f}
                                                     : Vec4{-1.0f, 3.0f, 0.25f, 1.0f};
                Pair pr;
                pr.set(tex, makeState(Filter::Linear, Filter::Linear, Filter::None, mu, mv, border));
                std::vector<float> u(static_cast<size_t>(count)), v(static_cast<size_t>(count));
                for (int i = 0; i < count; ++i) u[size_t(i)] = nastyCoord(rng, 30), v[size_t(i)] = nastyCoord(rng, 18);
                for (Precision p : {Precision::Fx8, Precision::Fx12})
                    bad += compareSpan(pr, p, u.data(), v.data(), count, false);
                pr.set(tex, makeState(Filter::Point, Filter::Point, Filter::None, mu, mv, border));
                bad += compareSpan(pr, Precision::Fx8, u.data(), v.data(), count, false);
            }
        }
    });
    CHECK(bad == 0);
}

TEST_CASE("sampler fast: mip levels chosen per quad equal the reference", "[sampler][fast]") {
    std::mt19937 rng(4242);
    int bad = 0;
    uint64_t fastLanes = 0;
    testutil::forEachSimdLevel([&](SimdLevel) {
        for (TexFormat f : {TexFormat::A8R8G8B8, TexFormat::L8, TexFormat::V8U8}) {
            const uint32_t w = 64, h = 24;
            auto tex = randomTexture(rng, f, w, h, fullMipCount(w, h, 1));
            for (Filter mip : {Filter::None, Filter::Point, Filter::Linear})
                for (Filter minF : {Filter::Point, Filter::Linear})
                    for (Filter magF : {Filter::Point, Filter::Linear})
                        for (TextureAddress mode : kModes)
                            for (Precision p : {Precision::Fx8, Precision::Fx12}) {
                                Pair pr;
                                pr.set(tex, makeState(minF, magF, mip, mode, kModes[rng() % 5], {0, 1, 0, 1}));
                                // Quads with footprints from magnified (0.3 texel) to beyond the last level.
                                const int count = 1 + int(rng() % kMaxSpan);
                                std::vector<float> u(static_cast<size_t>(count)), v(static_cast<size_t>(count));
                                const float scales[] = {0.3f, 1.0f, 1.5f, 2.0f, 3.7f, 8.0f, 40.0f, 100.0f};
                                // Neighbouring quads often share a level, so runs of several quads form;
                                // or every quad takes a footprint of its own (as a dependent read's do),
                                // and the fast path samples the span set by set.
                                const bool ownLevels = rng() % 2 == 0;
                                for (int q = 0; q < count; q += 4) {
                                    const float s = ownLevels ? scales[rng() % 8] * (0.5f + float(rng() % 64) / 32.0f)
                                                              : scales[(q / 16 + rng() % 2) % 8];
                                    const float u0 = nastyCoord(rng, w), v0 = nastyCoord(rng, h);
                                    const float du[4] = {0, s / w, 0, s / w}, dv[4] = {0, 0, s / h, s / h};
                                    for (int k = 0; k < 4 && q + k < count; ++k)
                                        u[size_t(q + k)] = u0 + du[k], v[size_t(q + k)] = v0 + dv[k];
                                }
                                bad += compareSpan(pr, p, u.data(), v.data(), count, true);
                                bad += compareSpan(pr, p, u.data(), v.data(), count, false);
                                fastLanes += pr.fast.fastLanes();
                            }
        }
    });
    CHECK(bad == 0);
    CHECK(fastLanes > 10000);
}

TEST_CASE("sampler fast: screen-aligned taps on a 1080p-shaped texture", "[sampler][fast]") {
    // The pattern of a full-screen pass: one row of lanes, u stepping by one texel, fixed
    // sub-texel offsets (half-texel blur taps, exact centres, and a 2:1 downsample).
    std::mt19937 rng(5);
    auto tex = randomTexture(rng, TexFormat::A8R8G8B8, 1920, 1080, 1);
    int bad = 0;
    testutil::forEachSimdLevel([&](SimdLevel) {
        for (TextureAddress mode : {TextureAddress::Clamp, TextureAddress::Wrap, TextureAddress::Mirror})
            for (float offset : {0.0f, 0.5f, -0.5f, 0.25f, 1.0f})
                for (float step : {1.0f, 2.0f, 0.5f})
                    for (int row : {0, 1, 539, 1079}) {
                        Pair pr;
                        pr.set(tex, makeState(Filter::Linear, Filter::Linear, Filter::None, mode, mode, {0, 0, 0, 0}));
                        std::vector<float> u(kMaxSpan), v(kMaxSpan, (float(row) + 0.5f + offset) / 1080.0f);
                        const int x0 = int(rng() % 1900);
                        for (int i = 0; i < kMaxSpan; ++i)
                            u[size_t(i)] = (float(x0 + i) * step + 0.5f + offset) / 1920.0f;
                        bad += compareSpan(pr, Precision::Fx8, u.data(), v.data(), kMaxSpan, false);
                        // The same pass as 2x2 quads (TL TR BL BR), as the rasteriser sends them.
                        for (int i = 0; i < kMaxSpan; ++i) {
                            const int px = x0 + 2 * (i / 4) + i % 2, py = row + (i / 2) % 2;
                            u[size_t(i)] = (float(px) * step + 0.5f + offset) / 1920.0f;
                            v[size_t(i)] = (float(py) + 0.5f + offset) / 1080.0f;
                        }
                        bad += compareSpan(pr, Precision::Fx8, u.data(), v.data(), kMaxSpan, true);
                        bad += compareSpan(pr, Precision::Fx12, u.data(), v.data(), 4 * int(1 + rng() % 64), true);
                    }
    });
    CHECK(bad == 0);
}
