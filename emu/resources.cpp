// Device stage: resource storage. Level sizes and pitches, allocation, D3DUSAGE_AUTOGENMIPMAP
// generation (box filter, rounded half-even in the stored representation) and the hand-over of
// a resource's levels to the sampler's immutable ps11::Texture.
#include "emu/resources.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "ps11/precision.h"

namespace emu {

namespace {

uint32_t extentAt(uint32_t size, uint32_t level) { return level >= 32 ? 1 : std::max<uint32_t>(1, size >> level); }

// A bit field of a signed (bump) format: shift, width, signed.
struct Field {
    int shift, bits;
    bool isSigned;
};

// The stored fields of a signed (bump) format, from its row: its channels' fields and the pad (X).
int fieldsOf(const FormatInfo& f, Field* out) {
    if (f.cls != FormatClass::Signed) return 0;
    int n = 0;
    auto add = [&](const ps11::Channel& ch) {
        if (ch.kind != ps11::ChannelKind::Snorm && ch.kind != ps11::ChannelKind::Unorm) return;
        for (int i = 0; i < n; ++i)
            if (out[i].shift == ch.shift) return;
        out[n++] = {ch.shift, ch.bits, ch.kind == ps11::ChannelKind::Snorm};
    };
    for (const ps11::Channel& ch : f.rgba) add(ch);
    if (f.pad.bits) add({ps11::ChannelKind::Unorm, f.pad.shift, f.pad.bits});
    return n;
}

int64_t fieldValue(uint32_t w, const Field& f) {
    const uint32_t mask = f.bits == 32 ? ~0u : (uint32_t(1) << f.bits) - 1;
    const uint32_t v = (w >> f.shift) & mask;
    if (!f.isSigned) return int64_t(v);
    const uint32_t m = uint32_t(1) << (f.bits - 1);
    return int64_t(int32_t(v ^ m) - int32_t(m));
}

uint32_t packField(int64_t v, const Field& f) {
    const uint32_t mask = (uint32_t(1) << f.bits) - 1;
    return (uint32_t(v) & mask) << f.shift;
}

// One level from the previous one: texel (x, y, z) averages source texels 2x+dx, 2y+dy, 2z+dz
// (dx, dy, dz in {0, 1}) clamped to the source extent, as ps11/texture.cpp's generated chains.
void boxLevel(const Image& src, Image& dst, bool volume) {
    const FormatInfo& f = *src.format;
    const int n = volume ? 8 : 4;
    Field fields[4];
    const int nFields = fieldsOf(f, fields);
    for (uint32_t z = 0; z < dst.depth; ++z)
        for (uint32_t y = 0; y < dst.height; ++y)
            for (uint32_t x = 0; x < dst.width; ++x) {
                const uint8_t* taps[8];
                int k = 0;
                for (uint32_t dz = 0; dz < (volume ? 2u : 1u); ++dz)
                    for (uint32_t dy = 0; dy < 2; ++dy)
                        for (uint32_t dx = 0; dx < 2; ++dx)
                            taps[k++] =
                                src.texel(std::min(2 * x + dx, src.width - 1), std::min(2 * y + dy, src.height - 1),
                                          std::min(2 * z + dz, src.depth - 1));
                uint8_t* out = dst.texel(x, y, z);
                switch (f.cls) {
                    case FormatClass::Unorm8:  // every byte is one channel
                        for (uint32_t b = 0; b < f.bytes; ++b) {
                            int64_t s = 0;
                            for (int i = 0; i < n; ++i) s += taps[i][b];
                            out[b] = uint8_t(ps11::roundHalfEven(s, n));
                        }
                        break;
                    case FormatClass::Signed: {
                        uint32_t word = 0;
                        for (int c = 0; c < nFields; ++c) {
                            int64_t s = 0;
                            for (int i = 0; i < n; ++i) s += fieldValue(loadWord(taps[i], f.bytes), fields[c]);
                            word |= packField(ps11::roundHalfEven(s, n), fields[c]);
                        }
                        for (uint32_t b = 0; b < f.bytes; ++b) out[b] = uint8_t(word >> (8 * b));
                        break;
                    }
                    case FormatClass::Float: {
                        std::array<double, 4> s{};
                        for (int i = 0; i < n; ++i) {
                            // Float texels: no signed channel, the decode rule is not used.
                            std::array<float, 4> v = decodeTexel(f, taps[i], ps11::SignedDecode::Snorm);
                            for (size_t c = 0; c < 4; ++c) s[c] += double(v[c]);
                        }
                        std::array<float, 4> avg;
                        for (size_t c = 0; c < 4; ++c) avg[c] = float(s[c] / n);
                        encodeFloat(f, avg, out);
                        break;
                    }
                    case FormatClass::Depth:
                        break;
                }
            }
}

}  // namespace

uint32_t rowPitchOf(const FormatInfo& f, uint32_t width) { return (width * f.bytes + 3u) & ~3u; }

uint64_t resourceBytes(const FormatInfo& f, uint32_t width, uint32_t height, uint32_t depth, uint32_t levels) {
    uint64_t total = 0;
    for (uint32_t k = 0; k < levels; ++k)
        total += uint64_t(rowPitchOf(f, extentAt(width, k))) * extentAt(height, k) * extentAt(depth, k);
    return total;
}

void ImageBytes::assign(size_t n, uint8_t v) {
    view(std::make_shared<uint8_t[]>(n, v), 0, n);
}

void ImageBytes::copyFrom(const ImageBytes& o) {
    if (!o.m_data) {
        *this = ImageBytes{};
        return;
    }
    assign(o.m_size, 0);
    std::memcpy(m_data, o.m_data, m_size);
}

void allocateLevels(Resource& r, uint32_t width, uint32_t height, uint32_t depth, uint32_t levels) {
    r.levels.resize(levels);
    size_t total = 0;
    for (uint32_t k = 0; k < levels; ++k) {
        Image& im = r.levels[k];
        im.format = r.format;
        im.width = extentAt(width, k);
        im.height = extentAt(height, k);
        im.depth = extentAt(depth, k);
        im.rowPitch = rowPitchOf(*r.format, im.width);
        im.slicePitch = uint64_t(im.rowPitch) * im.height;
        total += size_t(im.slicePitch * im.depth);
    }
    std::shared_ptr<uint8_t[]> store = std::make_shared<uint8_t[]>(total);
    size_t offset = 0;
    for (Image& im : r.levels) {
        const size_t n = size_t(im.slicePitch * im.depth);
        im.bytes.view(store, offset, n);
        offset += n;
    }
    r.locked.assign(levels, 0);
    r.lockedReadOnly.assign(levels, 0);
}

void generateMips(Resource& r) {
    const bool volume = r.kind == ResourceKind::VolumeTexture;
    for (size_t k = 1; k < r.levels.size(); ++k) boxLevel(r.levels[k - 1], r.levels[k], volume);
    r.mipsDirty = false;
}

void detachStore(Resource& r) {
    if (r.levels.empty()) return;
    const std::shared_ptr<uint8_t[]> old = r.store();
    size_t total = 0;
    for (const Image& im : r.levels) total += im.bytes.size();
    std::shared_ptr<uint8_t[]> store(new uint8_t[total]);  // every byte copied below
    std::memcpy(store.get(), old.get(), total);
    for (Image& im : r.levels) im.bytes.view(store, size_t(im.bytes.data() - old.get()), im.bytes.size());
}

std::shared_ptr<const ps11::Texture> makeSampledTexture(const Resource& r, ps11::SignedDecode decode, bool copy,
                                                       bool padOnes, std::string& error) {
    // The levels are handed over in D3D's memory layout (ps11::Texture::fromLevels): read in
    // place for A8R8G8B8, the float formats and (padOnes) X8R8G8B8, a per-texel expansion for the
    // other formats. No transient per-texel model.
    std::vector<ps11::TextureLevelBytes> levels(r.levels.size());
    for (size_t k = 0; k < r.levels.size(); ++k) {
        const Image& im = r.levels[k];
        levels[k] = {im.width, im.height, im.depth, im.bytes.data(), im.rowPitch, size_t(im.slicePitch)};
    }
    std::optional<ps11::Texture> t = ps11::Texture::fromLevels(
        r.format->texFormat, r.kind == ResourceKind::VolumeTexture, levels.data(), levels.size(), decode, error,
        copy || r.levels.empty() ? std::shared_ptr<const void>{} : std::shared_ptr<const void>(r.store()), padOnes);
    if (!t) return nullptr;
    return std::make_shared<const ps11::Texture>(std::move(*t));
}

}  // namespace emu
