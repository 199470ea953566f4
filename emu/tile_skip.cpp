// Tile skipping (emu/tile_skip.h, docs/device.md "Tile skipping").
#include "emu/tile_skip.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#include "emu/thread_pool.h"
#include "emu/vertex.h"
#include "ps11/diagnostics.h"
#include "ps11/texture.h"

namespace emu {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint64_t kParallelScanTexels = 1u << 18;

// Texel indices [i0, i1] of one axis as the address mode maps them into [0, n − 1]: `a`..`b`
// (a > b: none), `border` when some index falls on the border colour.
void addressAxis(ps11::TextureAddress mode, int64_t i0, int64_t i1, int64_t n, int64_t& a, int64_t& b, bool& border) {
    if (i0 >= 0 && i1 <= n - 1) {
        a = i0, b = i1;
        return;
    }
    switch (mode) {
        case ps11::TextureAddress::Clamp:
            a = std::clamp<int64_t>(i0, 0, n - 1), b = std::clamp<int64_t>(i1, 0, n - 1);
            return;
        case ps11::TextureAddress::Border:
            border = true;
            a = std::max<int64_t>(i0, 0), b = std::min<int64_t>(i1, n - 1);
            return;
        default:  // Wrap, Mirror, MirrorOnce: anywhere
            a = 0, b = n - 1;
            return;
    }
}

// The lookups of a stage without a texture: (0, 0, 0, 1).
void unboundLookups(ps11::ValueRange4& out) {
    for (int c = 0; c < 4; ++c) out[size_t(c)] = ps11::ValueRange::point(c == 3 ? 1 : 0);
}

// Whether an axis of the sampler may reach the border colour (somewhere in the texture).
bool mayReachBorder(const ps11::SamplerState& ss) {
    return ss.addressU == ps11::TextureAddress::Border || ss.addressV == ps11::TextureAddress::Border;
}

// The lookups' range from the texels' range. fx filters are convex integer sums rounded to the
// grid: inside the texels' range. Float lerps (1 − f)·a + f·b may leave it by rounding: widened
// by a relative 2⁻²⁰, except zeros, whose lerps are zeros.
ps11::ValueRange lookupRange(float lo, float hi, bool nan, bool negZero, bool fx) {
    ps11::ValueRange r;
    if (!std::isfinite(lo) || !std::isfinite(hi)) nan = true;  // ∞ · 0 in a lerp
    r.nan = nan;
    if (fx) return ps11::ValueRange{double(lo), double(hi), false, false};
    if (lo == 0 && hi == 0) {
        r.lo = r.hi = 0;
        r.negZero = negZero;
        return r;
    }
    const double m = std::max(std::fabs(double(lo)), std::fabs(double(hi))) * std::ldexp(1.0, -20);
    r.lo = lo >= 0 ? std::max(0.0, double(lo) - m) : double(lo) - m;
    r.hi = hi <= 0 ? std::min(0.0, double(hi) + m) : double(hi) + m;
    r.negZero = negZero || r.lo < 0;
    return r;
}

}  // namespace

RowWindow TileDecision::window(int x0, int x1) const {
    RowWindow w;
    w.x0 = x0;
    w.x1 = x1;
    w.mode = action == TileAction::Fill ? RowMode::Fill : action == TileAction::Copy ? RowMode::Copy : RowMode::Shade;
    w.copyTap = copyTap;
    w.copyMask = copyMask;
    w.grid = grid;
    w.value = value;
    return w;
}

std::unique_ptr<TileSkipper> TileSkipper::create(const ps11::Program& program, const DrawCall& call,
                                                 const ps11::TapPlan& plan, ThreadPool& pool, bool scan) {
    ps11::IntervalSetup setup;
    setup.options = ps11::executorOptionsFor(call.hardware);
    for (size_t i = 0; i < setup.constants.size() && i < call.program.constants.size(); ++i)
        setup.constants[i] = call.program.constants[i];
    setup.stagesKnown = true;
    for (size_t s = 0; s < setup.stages.size(); ++s) setup.stages[s] = call.program.stages[s];
    ps11::Diagnostics diags;
    std::optional<ps11::IntervalEvaluator> eval = ps11::IntervalEvaluator::create(program, setup, diags);
    if (!eval || eval->texcoordSetsRead() != 0 || eval->dependentLookupStages() != 0) return nullptr;
    auto sk = std::unique_ptr<TileSkipper>(new TileSkipper());
    static std::atomic<uint64_t> ids{0};
    sk->m_id = ++ids;
    sk->m_fx = ps11::isFixedPoint(call.hardware.precision);
    sk->m_grid = double(eval->profile().g);
    for (int t = 0; t < plan.count; ++t) {
        Stage& st = sk->m_stages[plan.stage[size_t(t)]];
        st.tap = st.tap == -1 && !st.read ? t : -2;
        st.read = true;
        st.coordSet = plan.coordSet[size_t(t)];
    }
    for (int s = 0; s < 8; ++s) {
        Stage& st = sk->m_stages[size_t(s)];
        if (st.tap < 0) st.tap = -1;
        const bool plain = (eval->plainLookupStages() >> s) & 1;
        if (plain && !st.read) return nullptr;  // a lookup the row path does not make
        st.read = plain;
        if (!plain) continue;
        st.texture = call.textures[size_t(s)];
        st.sampler = call.samplers[size_t(s)];
        if (!st.texture) continue;
        if (!ps11::hasTexelTiles(*st.texture)) return nullptr;
        st.tiles = st.texture->texelTiles();
        if (st.tiles || !scan) continue;
        // First read of this texture (of this generation): its facts, tile rows over the workers.
        // Where the device knew them uniform (cleared whole, then drawn into in places), only
        // the tiles drawn into since are scanned (ps11::uniformTileRange).
        auto tiles = std::make_shared<ps11::TexelTiles>();
        ps11::prepareTexelTiles(*st.texture, *tiles);
        const ps11::Texture& tex = *st.texture;
        const std::shared_ptr<const std::vector<uint8_t>> stale = tex.uniformTiles();
        ps11::TexelRange uniform;
        const bool known = stale && ps11::uniformTileRange(tex, *tiles, *stale, uniform);
        uint64_t texels = uint64_t(tiles->width) * tiles->height;
        if (known) {
            const uint64_t perTile = uint64_t(tiles->side) * tiles->side;
            texels = perTile * uint64_t(std::count(stale->begin(), stale->end(), uint8_t(1)));
        }
        auto scanRows = [&](uint32_t ty0, uint32_t ty1) {
            if (known)
                ps11::fillUniformTiles(tex, *tiles, *stale, uniform, ty0, ty1);
            else
                ps11::scanTexelTiles(tex, *tiles, ty0, ty1);
        };
        // Over the workers only where the scan outweighs waking them (about a megabyte of texels).
        if (texels < kParallelScanTexels) {
            scanRows(0, tiles->tilesY);
        } else {
            const int workers = int(std::clamp<uint32_t>(tiles->tilesY / 4, 1, uint32_t(pool.size())));
            pool.run(workers, [&](int w) {
                scanRows(tiles->tilesY * uint32_t(w) / uint32_t(workers),
                         tiles->tilesY * uint32_t(w + 1) / uint32_t(workers));
            });
        }
        st.texture->keepTexelTiles(tiles);
        st.tiles = std::move(tiles);
    }
    // The whole texture's lookup ranges (TileSkipper::widenedCopy): every texel, and the border
    // colour wherever an axis may reach it.
    // (Stages reading one texture, as a blur's taps do, take its whole range once.)
    sk->m_widens = scan && eval->colorsRead() == 0;
    const ps11::TexelTiles* wholeOf = nullptr;
    ps11::TexelRange whole;
    for (int s = 0; s < 8 && sk->m_widens; ++s) {
        Stage& st = sk->m_stages[size_t(s)];
        if (!st.read || !st.texture) continue;
        const bool border = mayReachBorder(st.sampler);
        if (st.tiles.get() != wholeOf) wholeOf = st.tiles.get(), whole = st.tiles->whole();
        sk->m_widens = st.tiles->width > 0 && st.tiles->height > 0 && sk->lookupRanges(st, whole, border, st.whole);
    }
    const uint8_t v = eval->colorsRead();
    for (int k = 0; k < 2; ++k)
        if ((v >> k) & 1)
            for (int c = 0; c < 4; ++c) sk->m_colorAttrs |= uint64_t(1) << ((k ? kAttrSpecular : kAttrDiffuse) + c);
    sk->m_colorAttrs &= call.usedAttributes;
    const MergeState& m = call.merge;
    const D3DFORMAT f = call.target.color ? call.target.color->format->format : D3DFMT_UNKNOWN;
    const bool addOne = m.srcBlend == D3DBLEND_ONE && m.dstBlend == D3DBLEND_ONE && m.blendOp == D3DBLENDOP_ADD;
    const bool addOneAlpha = !m.separateAlpha || (m.srcBlendAlpha == D3DBLEND_ONE && m.dstBlendAlpha == D3DBLEND_ONE &&
                                                  m.blendOpAlpha == D3DBLENDOP_ADD);
    sk->m_zeroAddIsNoOp = m.blend && addOne && addOneAlpha && !m.alphaTest && !m.fog && !m.depthTest && !m.depthWrite &&
                          f == D3DFMT_A8R8G8B8;  // an X8R8G8B8 store sets the X byte
    sk->m_writesNothing = m.writesNothing();
    sk->m_eval = std::move(eval);
    return sk;
}

namespace {

bool sameRange(const ps11::ValueRange& a, const ps11::ValueRange& b) {
    return a.lo == b.lo && a.hi == b.hi && a.negZero == b.negZero && a.nan == b.nan;
}

}  // namespace

bool TileSkipper::lookupRanges(const Stage& st, ps11::TexelRange r, bool border, ps11::ValueRange4& out) const {
    if (border) {
        // fx samplers take the border colour to the grid: within one step of it.
        const float e = m_fx ? float(1.0 / m_grid) : 0.0f;
        ps11::TexelRange b;
        for (int c = 0; c < 4; ++c) {
            const float x = st.sampler.border[size_t(c)];
            if (std::isnan(x)) b.nan |= uint8_t(1u << c);
            if (x == 0 && std::signbit(x)) b.negZero |= uint8_t(1u << c);
            b.lo[size_t(c)] = m_fx ? std::max(0.0f, x - e) : x;
            b.hi[size_t(c)] = x + e;
        }
        r.add(b);
    }
    for (int c = 0; c < 4; ++c) {
        const bool nan = (r.nan >> c) & 1;
        if (r.lo[size_t(c)] > r.hi[size_t(c)]) {  // no value but NaN, or nothing known
            if (!nan) return false;
            out[size_t(c)] = ps11::ValueRange::any();
            continue;
        }
        out[size_t(c)] = lookupRange(r.lo[size_t(c)], r.hi[size_t(c)], nan, (r.negZero >> c) & 1, m_fx);
    }
    return true;
}

template <class F>
bool TileSkipper::stageRanges(ps11::IntervalInputs& in, F bound) const {
    for (int s = 0; s < 8; ++s) {
        const Stage& st = m_stages[size_t(s)];
        if (!st.read) continue;
        ps11::ValueRange4& out = in.stages[size_t(s)].value;
        if (!st.texture) {
            unboundLookups(out);
            continue;
        }
        if (!bound(st, out)) return false;
    }
    return true;
}

TileDecision TileSkipper::anyData() const {
    ps11::IntervalInputs in;
    const bool known = stageRanges(in, [&](const Stage& st, ps11::ValueRange4& out) {
        ps11::TexelRange r;  // 8-bit texels: [0, 1]; others: anything, NaN included
        if (st.texture->storage() == ps11::TexelStorage::Unorm8) {
            r.lo = {0, 0, 0, 0}, r.hi = {1, 1, 1, 1};
        } else {
            r.nan = 0xf;
        }
        return lookupRanges(st, r, mayReachBorder(st.sampler), out);
    });
    // (Colours stay anything: IntervalInputs' default.)
    return known ? evaluate(in) : TileDecision{};
}

TileDecision TileSkipper::decide(const TriangleSetup* const* tris, size_t count, int x0, int x1, int y0, int y1,
                                 TileMemo& memo) const {
    TileDecision shade;
    if (count == 0 || x0 >= x1 || y0 >= y1) return shade;
    if (memo.skipper != m_id) memo = TileMemo{}, memo.skipper = m_id;
    // Only the ranges this draw reads are written (the rest stay unknown from the start).
    ps11::IntervalInputs& in = memo.in;
    // Each stage's footprint: the texels its coordinates reach over the tile (u affine in x
    // alone, v in y alone on the row paths, on every triangle), a bilinear footprint (also
    // covering point sampling) and one texel more each side for the samplers' own rounding of
    // coordinates, after addressing. Stages that read one texture's facts with the same
    // addressing and border (a blur's taps) take the range of the union of their footprints,
    // looked up once: a claim over the wider range holds over each one's.
    struct Footprint {
        int64_t a0 = 0, a1 = -1, b0 = 0, b1 = -1;  // texels [a0, a1] x [b0, b1] (empty: none)
        bool border = false;
        int leader = -1;  // the stage whose union this one joined (itself for the first)
    };
    std::array<Footprint, 8> feet{};
    for (int s = 0; s < 8; ++s) {
        const Stage& st = m_stages[size_t(s)];
        if (!st.read || !st.texture) continue;
        double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
        for (size_t i = 0; i < count; ++i) {
            float u[2], v[2];
            columnU(*tris[i], st.coordSet, x0, 1, &u[0]);
            columnU(*tris[i], st.coordSet, x1 - 1, 1, &u[1]);
            v[0] = rowV(*tris[i], st.coordSet, y0);
            v[1] = rowV(*tris[i], st.coordSet, y1 - 1);
            for (int k = 0; k < 2; ++k) {
                if (!std::isfinite(u[k]) || !std::isfinite(v[k]) || std::fabs(u[k]) > 1e6f || std::fabs(v[k]) > 1e6f)
                    return shade;
                umin = std::min(umin, double(u[k])), umax = std::max(umax, double(u[k]));
                vmin = std::min(vmin, double(v[k])), vmax = std::max(vmax, double(v[k]));
            }
        }
        const ps11::TexelTiles& tiles = *st.tiles;
        const int64_t W = tiles.width, H = tiles.height;
        const int64_t i0 = int64_t(std::floor(umin * double(W) - 0.5)) - 1, i1 = int64_t(std::floor(umax * double(W) - 0.5)) + 2;
        const int64_t j0 = int64_t(std::floor(vmin * double(H) - 0.5)) - 1, j1 = int64_t(std::floor(vmax * double(H) - 0.5)) + 2;
        Footprint f;
        addressAxis(st.sampler.addressU, i0, i1, W, f.a0, f.a1, f.border);
        addressAxis(st.sampler.addressV, j0, j1, H, f.b0, f.b1, f.border);
        f.leader = s;
        for (int l = 0; l < s; ++l) {
            const Stage& o = m_stages[size_t(l)];
            if (feet[size_t(l)].leader != l || o.tiles != st.tiles || o.sampler.addressU != st.sampler.addressU ||
                o.sampler.addressV != st.sampler.addressV ||
                std::memcmp(o.sampler.border.data(), st.sampler.border.data(), sizeof st.sampler.border) != 0)
                continue;
            Footprint& u = feet[size_t(l)];
            u.border = u.border || f.border;
            if (f.a0 <= f.a1 && f.b0 <= f.b1) {
                if (u.a0 <= u.a1 && u.b0 <= u.b1) {
                    u.a0 = std::min(u.a0, f.a0), u.a1 = std::max(u.a1, f.a1);
                    u.b0 = std::min(u.b0, f.b0), u.b1 = std::max(u.b1, f.b1);
                } else {
                    u.a0 = f.a0, u.a1 = f.a1, u.b0 = f.b0, u.b1 = f.b1;
                }
            }
            f.leader = l;
            break;
        }
        feet[size_t(s)] = f;
    }
    const bool known = stageRanges(in, [&](const Stage& st, ps11::ValueRange4& out) {
        const int s = int(&st - m_stages.data());
        const Footprint& f = feet[size_t(s)];
        if (f.leader != s) {
            out = in.stages[size_t(f.leader)].value;  // (the leader comes first: looked up already)
            return true;
        }
        ps11::TexelRange r;
        if (f.a0 <= f.a1 && f.b0 <= f.b1)
            r = st.tiles->over(uint32_t(f.a0), uint32_t(f.b0), uint32_t(f.a1), uint32_t(f.b1));
        return lookupRanges(st, r, f.border, out);
    });
    if (!known) return shade;
    // Colours: constant on a triangle, or affine (extremes at the tile's corners, widened for
    // the float rounding of the interpolation).
    for (int k = 0; k < 2; ++k)
        for (int c = 0; c < 4; ++c) {
            const int attr = (k ? kAttrSpecular : kAttrDiffuse) + c;
            if (!((m_colorAttrs >> attr) & 1)) continue;
            double lo = kInf, hi = -kInf;
            bool affine = false, negZero = false;
            for (size_t i = 0; i < count; ++i) {
                const TriangleSetup& s = *tris[i];
                if ((s.constMask >> attr) & 1) {
                    const float x = s.constValue[size_t(attr)];
                    if (!std::isfinite(x)) return shade;
                    negZero |= x == 0 && std::signbit(x);
                    lo = std::min(lo, double(x)), hi = std::max(hi, double(x));
                    continue;
                }
                affine = true;
                const Plane& p = s.attr[size_t(attr)];
                for (int y : {y0, y1 - 1})
                    for (int x : {x0, x1 - 1}) {
                        const double val = double(float(planeRowBase(p, s.ox, s.oy, y)) + float(p.dx) * float(x));
                        if (!std::isfinite(val)) return shade;
                        lo = std::min(lo, val), hi = std::max(hi, val);
                    }
            }
            if (affine) {
                const double m = (std::fabs(lo) + std::fabs(hi)) * 1e-6 + 1e-30;
                lo -= m, hi += m, negZero = true;
            }
            in.color[size_t(k)][size_t(c)] = ps11::ValueRange{lo, hi, negZero, false};
        }
    // The same ranges as the worker's last tile: the same decision.
    bool same = memo.valid;
    for (int s = 0; s < 8 && same; ++s)
        if (m_stages[size_t(s)].read)
            for (int c = 0; c < 4 && same; ++c) same = sameRange(in.stages[size_t(s)].value[size_t(c)], memo.last.stages[size_t(s)].value[size_t(c)]);
    for (int k = 0; k < 2 && same; ++k)
        for (int c = 0; c < 4 && same; ++c) same = sameRange(in.color[size_t(k)][size_t(c)], memo.last.color[size_t(k)][size_t(c)]);
    if (same) return memo.decision;
    if (m_widens) {
        const std::optional<TileDecision> copy = widenedCopy(in, memo);
        if (copy) return *copy;
    }
    memo.decision = evaluate(in);
    memo.last = in;
    memo.valid = true;
    return memo.decision;
}

std::optional<TileDecision> TileSkipper::widenedCopy(const ps11::IntervalInputs& in, TileMemo& memo) const {
    // The tile's inputs with every stage whose range is not one value widened to the whole
    // texture's: a claim over the wider ranges holds over the tile's (the evaluator's claims hold
    // for every input inside its ranges), and tiles that differ only in the widened stages share
    // one evaluation (a composite's scene tiles over a zero glare).
    ps11::IntervalInputs& wide = memo.wide;
    uint8_t widened = 0;
    for (int s = 0; s < 8; ++s) {
        const Stage& st = m_stages[size_t(s)];
        if (!st.read) continue;
        const ps11::ValueRange4& v = in.stages[size_t(s)].value;
        bool point = true;
        for (const ps11::ValueRange& c : v) point = point && !c.nan && c.lo == c.hi;
        wide.stages[size_t(s)].value = point || !st.texture ? v : st.whole;
        if (!point && st.texture) widened |= uint8_t(1u << s);
    }
    if (!widened) return std::nullopt;  // the tile's own evaluation is the same
    TileMemo::Widened* hit = nullptr;
    for (TileMemo::Widened& w : memo.widened) {
        if (!w.valid || w.stages != widened) continue;
        bool same = true;
        for (int s = 0; s < 8 && same; ++s)
            if (m_stages[size_t(s)].read)
                for (int c = 0; c < 4 && same; ++c)
                    same = sameRange(wide.stages[size_t(s)].value[size_t(c)], w.in.stages[size_t(s)].value[size_t(c)]);
        if (same) hit = &w;
    }
    if (!hit) {
        hit = &memo.widened[memo.nextWidened];
        memo.nextWidened = (memo.nextWidened + 1) % memo.widened.size();
        hit->valid = true;
        hit->stages = widened;
        hit->in = wide;
        hit->decision = evaluate(wide);
    }
    const TileDecision& d = hit->decision;
    if (d.action != TileAction::Copy) return std::nullopt;  // the tile's own ranges may say more
    // Taken only where a copied channel varies in the tile: there the tile's own evaluation can
    // claim no constant (the channel is a copy of a lookup that takes two values), so it would
    // not have filled or skipped the tile.
    int stage = -1;
    for (int s = 0; s < 8; ++s)
        if (m_stages[size_t(s)].read && m_stages[size_t(s)].tap == d.copyTap) stage = s;
    if (stage < 0) return std::nullopt;
    for (int c = 0; c < 4; ++c) {
        const ps11::ValueRange& v = in.stages[size_t(stage)].value[size_t(c)];
        if ((d.copyMask >> c) & 1 && !v.nan && v.lo < v.hi) return d;
    }
    return std::nullopt;
}

TileDecision TileSkipper::evaluate(const ps11::IntervalInputs& in) const {
    const TileDecision shade;
    ps11::IntervalResult r;
    m_eval->evaluate(in, r);
    if (r.kill != ps11::KillRange::Never || r.writesDepth) return shade;
    // Constant channels: the fill values (fx: the grid integer; float: the float, +0.0 for 0).
    TileDecision d;
    uint8_t constants = 0;
    bool zero = true;
    for (int c = 0; c < 4; ++c) {
        const ps11::ChannelInterval& ch = r.color[size_t(c)];
        if (!ch.constant) continue;
        constants |= uint8_t(1u << c);
        d.grid[size_t(c)] = m_fx ? ch.gridLo : 0;
        d.value[size_t(c)] = m_fx ? float(ch.gridLo) / float(m_grid) : (ch.lo == 0 ? 0.0f : float(ch.lo));
        zero = zero && (m_fx ? ch.gridLo == 0 : ch.lo == 0);
    }
    if (constants == 0xf) {
        d.action = m_writesNothing || (zero && m_zeroAddIsNoOp) ? TileAction::Skip : TileAction::Fill;
        return d;
    }
    // A copy: every channel the lookup's own or a constant.
    const int cs = r.channelCopyStage;
    if (cs >= 0 && cs < 8 && m_stages[size_t(cs)].tap >= 0 && (r.copyMask | constants) == 0xf) {
        d.action = TileAction::Copy;
        d.copyTap = m_stages[size_t(cs)].tap;
        d.copyMask = r.copyMask;
        for (int c = 0; c < 4; ++c)
            if ((r.copyMask >> c) & 1) d.grid[size_t(c)] = 0, d.value[size_t(c)] = 0;
        return d;
    }
    return shade;
}

}  // namespace emu
