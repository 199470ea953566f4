// Float textures read where their levels lie (ps11::Texture::fromLevels with an owner,
// Texture::floatTexels): A16B16G16R16F, A32B32G32R32F and R32F sample, bit for bit, as the same
// levels decoded into a copy do, in every profile, filter, address mode, mip chain and volume,
// and their texel values, grids and tile facts are the copy's.
#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "ps11/texture.h"
#include "ps11/texture_sampler.h"
#include "ps11/texture_tiles.h"

using namespace ps11;

namespace {

// A half's value from its definition (IEEE 754 binary16), in double.
double halfReference(uint16_t h) {
    const int sign = h >> 15, exponent = (h >> 10) & 31, mantissa = h & 1023;
    const double v = exponent == 0    ? std::ldexp(double(mantissa), -24)
                     : exponent == 31 ? (mantissa ? std::numeric_limits<double>::quiet_NaN()
                                                  : std::numeric_limits<double>::infinity())
                                      : std::ldexp(double(mantissa + 1024), exponent - 25);
    return sign ? -v : v;
}

// Random texel bytes for a float format, with the values that need care mixed in: NaNs, both
// infinities, −0.0, subnormals, and magnitudes beyond every profile's grid clamp.
std::vector<uint8_t> floatBytes(TexFormat f, size_t texels, std::mt19937& rng) {
    const FormatRow& row = formatRow(f);
    std::vector<uint8_t> out(texels * row.bytes);
    const uint16_t halves[] = {0x7e00, 0xfe01, 0x7c00, 0xfc00, 0x8000, 0x0001, 0x83ff, 0x7bff, 0xfbff, 0x3c00, 0x3800};
    const uint32_t floats[] = {0x7fc00000u, 0xffc00001u, 0x7f800000u, 0xff800000u, 0x80000000u,
                               0x00000001u, 0x4f000000u, 0xcf000000u, 0x3f800000u, 0x3e800000u};
    for (size_t i = 0; i < texels; ++i)
        for (const Channel& ch : row.rgba) {
            uint8_t* p = out.data() + i * row.bytes + ch.shift / 8;
            const bool special = rng() % 4 == 0;
            if (ch.kind == ChannelKind::Half) {
                // Random halves mostly in [0, 2): the values a render target holds.
                const uint16_t h = special ? halves[rng() % std::size(halves)] : uint16_t(rng() % 0x4000);
                std::memcpy(p, &h, 2);
            } else if (ch.kind == ChannelKind::Float) {
                float v = std::uniform_real_distribution<float>(-0.5f, 2.0f)(rng);
                if (special) std::memcpy(&v, &floats[rng() % std::size(floats)], 4);
                std::memcpy(p, &v, 4);
            }
        }
    return out;
}

// Level k's extents for a chain of `levels` from w × h × d.
std::vector<TextureLevelBytes> chain(const uint8_t* data, uint32_t bpt, uint32_t w, uint32_t h, uint32_t d,
                                     uint32_t levels) {
    std::vector<TextureLevelBytes> out;
    size_t at = 0;
    for (uint32_t k = 0; k < levels; ++k) {
        TextureLevelBytes l;
        l.width = std::max(1u, w >> k), l.height = std::max(1u, h >> k), l.depth = std::max(1u, d >> k);
        l.data = data + at;
        l.rowPitch = size_t(l.width) * bpt;
        l.slicePitch = l.rowPitch * l.height;
        at += l.slicePitch * l.depth;
        out.push_back(l);
    }
    return out;
}

bool sameBits(float a, float b) { return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b); }

}  // namespace

TEST_CASE("texture: halfToFloat gives every half's exact value", "[texture]") {
    for (uint32_t h = 0; h < 65536; ++h) {
        INFO("half 0x" << std::hex << h);
        const float got = halfToFloat(uint16_t(h));
        const double want = halfReference(uint16_t(h));
        if (std::isnan(want)) {
            // The quiet NaN with the half's sign (what the device's conversions have always read).
            CHECK(std::bit_cast<uint32_t>(got) == ((h & 0x8000u) ? 0xffc00000u : 0x7fc00000u));
        } else {
            CHECK(double(got) == want);
            CHECK(std::signbit(got) == bool(h & 0x8000u));
        }
    }
}

TEST_CASE("texture: float levels read in place sample as their decoded copy", "[texture][sampler]") {
    std::mt19937 rng(77);
    for (TexFormat f : {TexFormat::A16B16G16R16F, TexFormat::A32B32G32R32F, TexFormat::R32F})
        for (bool volume : {false, true}) {
            const uint32_t w = volume ? 6 : 13, h = volume ? 4 : 9, d = volume ? 5 : 1;
            const uint32_t levels = fullMipCount(w, h, d);
            const uint32_t bpt = bytesPerTexel(f);
            size_t texels = 0;
            for (uint32_t k = 0; k < levels; ++k)
                texels += size_t(std::max(1u, w >> k)) * std::max(1u, h >> k) * std::max(1u, d >> k);
            const std::vector<uint8_t> bytes = floatBytes(f, texels, rng);
            auto owned = std::shared_ptr<uint8_t[]>(new uint8_t[bytes.size()]);
            std::memcpy(owned.get(), bytes.data(), bytes.size());
            const std::vector<TextureLevelBytes> lv = chain(owned.get(), bpt, w, h, d, levels);
            std::string error;
            std::optional<Texture> in =
                Texture::fromLevels(f, volume, lv.data(), lv.size(), SignedDecode::Snorm, error, owned);
            std::optional<Texture> copy =
                Texture::fromLevels(f, volume, lv.data(), lv.size(), SignedDecode::Snorm, error);
            INFO(formatRow(f).name << (volume ? " volume" : " 2-D") << ": " << error);
            REQUIRE(in);
            REQUIRE(copy);
            CHECK(in->readsInPlace());
            CHECK_FALSE(copy->readsInPlace());
            // Only A32B32G32R32F's texels are the four float32 the other readers take as they are.
            CHECK((in->values() != nullptr) == (f == TexFormat::A32B32G32R32F));
            CHECK(in->floatTexels().base == owned.get());

            // Every texel's value and grids.
            for (int l = 0; l < int(levels); ++l) {
                const TextureLevelInfo& li = in->level(l);
                for (uint32_t z = 0; z < li.depth; ++z)
                    for (uint32_t y = 0; y < li.height; ++y)
                        for (uint32_t x = 0; x < li.width; ++x) {
                            const std::array<float, 4> a = in->texelValue(l, x, y, z), b = copy->texelValue(l, x, y, z);
                            for (size_t c = 0; c < 4; ++c) REQUIRE(sameBits(a[c], b[c]));
                            for (Precision p : {Precision::Fx8, Precision::Fx12})
                                REQUIRE(in->texelGrid(l, x, y, z, p) == copy->texelGrid(l, x, y, z, p));
                        }
            }

            // Level 0's tile facts.
            if (!volume) {
                TexelTiles ta, tb;
                prepareTexelTiles(*in, ta);
                prepareTexelTiles(*copy, tb);
                scanTexelTiles(*in, ta, 0, ta.tilesY);
                scanTexelTiles(*copy, tb, 0, tb.tilesY);
                REQUIRE(ta.tiles.size() == tb.tiles.size());
                for (size_t t = 0; t < ta.tiles.size(); ++t) {
                    CHECK(ta.tiles[t].lo == tb.tiles[t].lo);
                    CHECK(ta.tiles[t].hi == tb.tiles[t].hi);
                    CHECK(ta.tiles[t].nan == tb.tiles[t].nan);
                    CHECK(ta.tiles[t].negZero == tb.tiles[t].negZero);
                }
            }

            // Sampling: quads whose derivatives pick levels and blends of two, every filter and
            // address mode, in every profile.
            const auto shared = std::make_shared<const Texture>(std::move(*in));
            const auto decoded = std::make_shared<const Texture>(std::move(*copy));
            std::uniform_real_distribution<float> coord(-1.5f, 2.5f), step(0.0f, 0.6f);
            const int n = 64;
            std::vector<float> u(n), v(n), t(n);
            for (int q = 0; q < n; q += 4) {
                const float u0 = coord(rng), v0 = coord(rng), t0 = coord(rng), s = step(rng);
                for (int k = 0; k < 4; ++k) {
                    u[size_t(q + k)] = u0 + (k & 1) * s;
                    v[size_t(q + k)] = v0 + (k >> 1) * s;
                    t[size_t(q + k)] = t0 + (k & 1) * s * 0.5f;
                }
            }
            u[5] = std::nanf("");
            for (Filter filter : {Filter::Point, Filter::Linear})
                for (Filter mip : {Filter::None, Filter::Point, Filter::Linear})
                    for (TextureAddress mode : {TextureAddress::Wrap, TextureAddress::Mirror, TextureAddress::Clamp,
                                                TextureAddress::Border, TextureAddress::MirrorOnce})
                        for (Precision p : {Precision::Fx8, Precision::Fx12, Precision::Float, Precision::Ideal}) {
                            SamplerState st;
                            st.minFilter = st.magFilter = filter;
                            st.mipFilter = mip;
                            st.addressU = st.addressV = st.addressW = mode;
                            st.border = {0.25f, -1.0f, 3.0f, 0.5f};
                            TextureSampler sa, sb;
                            sa.bind(0, shared);
                            sb.bind(0, decoded);
                            sa.setSamplerState(0, st);
                            sb.setSamplerState(0, st);
                            std::array<std::vector<int32_t>, 4> ga, gb;
                            std::array<std::vector<float>, 4> fa, fb;
                            SampleResult ra, rb;
                            for (size_t c = 0; c < 4; ++c) {
                                ga[c].assign(n, -7), gb[c].assign(n, -7);
                                fa[c].assign(n, -7.0f), fb[c].assign(n, -7.0f);
                                ra.grid[c] = ga[c].data(), rb.grid[c] = gb[c].data();
                                ra.value[c] = fa[c].data(), rb.value[c] = fb[c].data();
                            }
                            SampleRequest req;
                            req.count = n;
                            req.quads = true;
                            req.dims = volume ? 3 : 2;
                            req.u = u.data(), req.v = v.data(), req.w = volume ? t.data() : nullptr;
                            req.precision = p;
                            sa.sample(req, ra);
                            sb.sample(req, rb);
                            INFO("filter " << int(filter) << " mip " << int(mip) << " address " << int(mode)
                                           << " profile " << precisionName(p));
                            for (size_t c = 0; c < 4; ++c) {
                                CHECK(ga[c] == gb[c]);
                                for (int i = 0; i < n; ++i) {
                                    const float x = fa[c][size_t(i)], y = fb[c][size_t(i)];
                                    // Both NaN, or the same bits.
                                    if (!(std::isnan(x) && std::isnan(y))) REQUIRE(sameBits(x, y));
                                }
                            }
                        }
        }
}
