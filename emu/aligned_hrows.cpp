// Device stage: the aligned-pass path's per-worker H-row cache (emu/aligned_pass.h HRowCache):
// finding or taking a slot per texel row and configuration, and building the H rows the vertical
// blends of emu/aligned_pass.cpp read (deinterleaved staged rows, combined or tabulated rows, a
// 4:1 reduction's pair sums, a point reduction's picked texels).
#include <cstring>
#include <memory>
#include <vector>

#include "emu/aligned_pass.h"
#include "emu/aligned_pass_kernels.h"

namespace emu {

namespace {

// Takes a slot for (row, key), whose hash `h` no slot has: the next slot, round the slots from
// the last one taken, used on neither the current pixel row (so every pointer handed out for a
// row stays valid until the next row) nor the one before, or a new one.
[[gnu::noinline]] HRowCache::Slot& takeSlot(HRowCache& cache, const uint8_t* row, const HConfig& key, uint64_t tableId,
                                            uint64_t h, uint32_t& hint) {
    // Not one used on this pixel row or the one before (the rows a magnified tap's next pixel row
    // most likely reads again): the first other from the clock hand (slots are taken in turn, so
    // the one taken is the longest filled; a scan for the least recently used cost more than the
    // misses it saved), or a new slot.
    const size_t n = cache.keys.size();
    size_t victim = n;
    for (size_t k = 0, i = n ? cache.hand % n : 0; k < n; ++k, i = i + 1 == n ? 0 : i + 1) {
        if (cache.stamps[i] + 1 < cache.stamp) {
            victim = i;
            break;
        }
    }
    cache.hand = victim + 1;
    if (victim == n) {
        cache.slots.push_back(std::make_unique<HRowCache::Slot>());
        cache.keys.push_back(0);
        cache.stamps.push_back(0);
    }
    HRowCache::Slot& sl = *cache.slots[victim];
    sl.row = row;
    sl.config = key;
    sl.config.tableId = tableId;
    cache.keys[victim] = h;
    cache.stamps[victim] = cache.stamp;
    hint = uint32_t(victim + 1);
    return sl;
}

// Finds the slot for (row, key) or takes one for it (takeSlot). `fresh` tells whether it must be
// filled. Inlined into hRow: the keys it builds stay in registers (a key stored to the stack
// and read back field by field stalled every lookup).
[[gnu::always_inline]] inline HRowCache::Slot& slotFor(HRowCache& cache, const uint8_t* row, const HConfig& key,
                                                       uint64_t tableId, bool& fresh) {
    // A cheap key over the fields that identify the row (never 0: 0 marks an empty slot); slots
    // with the key are then compared field by field.
    uint64_t h = (uint64_t(reinterpret_cast<uintptr_t>(row)) ^ (tableId * 0x9E3779B97F4A7C15ull) ^
                  (uint64_t(uint32_t(key.jlo)) << 40) ^ (uint64_t(uint32_t(key.wx) & 0xffu) << 32) ^
                  (uint64_t(uint32_t(key.phase)) << 24) ^ uint64_t(uint32_t(key.step)) << 16) *
                 0xff51afd7ed558ccdull;
    h |= 1;
    const size_t n = cache.keys.size();
    auto same = [&](size_t i) {
        const HRowCache::Slot& sl = *cache.slots[i];
        const HConfig& k = sl.config;
        return cache.keys[i] == h && sl.row == row && k.texels == key.texels && k.wx == key.wx && k.step == key.step &&
               k.phase == key.phase && k.jlo == key.jlo && k.jhi == key.jhi && k.tableId == tableId;
    };
    // The product's top bits: they depend on every bit of the key (its low bits only on the key's
    // low bits, the same for a row's configurations).
    uint32_t& hint = cache.hint[size_t(h >> 56)];
    size_t found = hint > 0 && hint <= n && same(hint - 1) ? hint - 1 : n;
    // (The scan reads the keys alone, side by side; a slot is looked at only where its key matches.)
    const uint64_t* keys = cache.keys.data();
    for (size_t i = 0; found == n && i < n; ++i)
        if (keys[i] == h && same(i)) found = i;
    if (found < n) {
        cache.stamps[found] = cache.stamp;
        hint = uint32_t(found + 1);
        fresh = false;
        return *cache.slots[found];
    }
    fresh = true;
    return takeSlot(cache, row, key, tableId, h, hint);
}

// Sizes a slot for n elements per plane (plus the kernels' padding) and returns its planes.
void slotPlanes(HRowCache::Slot& sl, int n, int pad, uint16_t* out[4]) {
    sl.stride = (n + pad + 15) & ~15;
    if (sl.data.size() < size_t(sl.stride) * 4) sl.data.resize(size_t(sl.stride) * 4);
    for (int c = 0; c < 4; ++c) out[c] = sl.data.data() + size_t(c) * size_t(sl.stride);
}

}  // namespace

void hRow(const AlignedKernels& kernels, HRowCache& cache, const uint8_t* row, const HConfig& config, uint64_t tableId,
          HRowRef& planes) {
    bool fresh = false;
    if (config.wx == -2) {  // tabulated: straight from the texel row, per column
        HRowCache::Slot& h = slotFor(cache, row, config, tableId, fresh);
        if (fresh) {
            const int n = config.jhi - config.jlo;
            uint16_t* out[4];
            slotPlanes(h, n, kHRowPad, out);
            kernels.buildTabulated(row, config.rowTexels, config.off0, config.off1, config.w, n, out, config.q16 ? 4 : 0);
            ++cache.built;
        } else {
            ++cache.hits;
        }
        planes = HRowRef{h.data.data(), size_t(h.stride)};
        return;
    }
    if (config.step == 4 && config.wx == 128 && (config.phase == 0 || config.phase == 2) &&
        4 * config.jhi <= config.rowTexels) {
        // A 4:1 reduction's pair sums straight from the texel row, both phases at once (the other
        // one into its own slot, where the draw's other taps on this texture most likely look).
        HRowCache::Slot& h = slotFor(cache, row, config, tableId, fresh);
        if (fresh) {
            HConfig partner = config;
            partner.phase = 2 - config.phase;
            bool partnerFresh = false;
            HRowCache::Slot& p = slotFor(cache, row, partner, tableId, partnerFresh);
            const int n = config.jhi - config.jlo;
            uint16_t *mine[4], *other[4];
            slotPlanes(h, n, kHRowPad, mine);
            if (partnerFresh) {
                slotPlanes(p, n, kHRowPad, other);
            } else {
                thread_local std::vector<uint16_t> spare;
                spare.resize(size_t((n + kHRowPad + 15) & ~15) * 4);
                for (int c = 0; c < 4; ++c) other[c] = spare.data() + size_t(c) * (spare.size() / 4);
            }
            const uint8_t* texels = row + size_t(16) * size_t(config.jlo);
            if (config.phase == 0)
                kernels.pairSums4(texels, n, mine, other);
            else
                kernels.pairSums4(texels, n, other, mine);
            cache.built += partnerFresh ? 2 : 1;
        } else {
            ++cache.hits;
        }
        planes = HRowRef{h.data.data(), size_t(h.stride)};
        return;
    }
    if (config.wx == 0 && config.step >= 2) {
        // A point reduction (kind A, one texel in `step`, a bright pass's 8:1): the texels it
        // reads, picked from the row and deinterleaved; no staged row, which would deinterleave
        // `step` times the texels used.
        HRowCache::Slot& h = slotFor(cache, row, config, tableId, fresh);
        if (fresh) {
            const int n = config.jhi - config.jlo;
            uint16_t* out[4];
            slotPlanes(h, n, kHRowPad, out);
            thread_local std::vector<uint32_t> picked;
            picked.resize(size_t(n));
            const uint8_t* texel = row + 4 * (size_t(config.step) * size_t(config.jlo) + size_t(config.phase));
            for (int j = 0; j < n; ++j, texel += 4 * size_t(config.step)) std::memcpy(&picked[size_t(j)], texel, 4);
            kernels.deinterleave(reinterpret_cast<const uint8_t*>(picked.data()), n, out);
            ++cache.built;
        } else {
            ++cache.hits;
        }
        planes = HRowRef{h.data.data(), size_t(h.stride)};
        return;
    }
    const HConfig stageKey{config.texels, -1, 0, 0, config.stageLo, config.stageHi, config.stageLo, config.stageHi};
    HRowCache::Slot& staged = slotFor(cache, row, stageKey, stageKey.tableId, fresh);
    const int first = config.step * config.jlo + config.phase - config.stageLo;  // staged element of jlo
    if (fresh) {
        uint16_t* out[4];
        slotPlanes(staged, config.stageHi - config.stageLo, kStagePad, out);
        kernels.deinterleave(row + size_t(config.stageLo) * 4, config.stageHi - config.stageLo, out);
        ++cache.staged;
    }
    if (config.step == 1 && config.wx == 0) {
        planes = HRowRef{staged.data.data() + size_t(first), size_t(staged.stride)};
        return;
    }
    HRowCache::Slot& h = slotFor(cache, row, config, tableId, fresh);
    if (fresh) {
        uint16_t* out[4];
        slotPlanes(h, config.jhi - config.jlo, kHRowPad, out);
        const uint16_t* const t[4] = {staged.data.data() + size_t(first),
                                      staged.data.data() + size_t(staged.stride) + size_t(first),
                                      staged.data.data() + 2 * size_t(staged.stride) + size_t(first),
                                      staged.data.data() + 3 * size_t(staged.stride) + size_t(first)};
        kernels.combine(t, config.jhi - config.jlo, config.step, config.wx, out);
        ++cache.built;
    } else {
        ++cache.hits;
    }
    planes = HRowRef{h.data.data(), size_t(h.stride)};
}


}  // namespace emu
