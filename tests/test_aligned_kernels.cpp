// The row paths' kernels and reductions: the fx8 store kernels and verticalStore against their
// rule, rows under a RowSource, 4:1 reductions straight from the texel row, point reductions, and
// clamped chains of products, against the quad path or a scalar model.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "emu/aligned_float.h"
#include "emu/aligned_pass.h"
#include "emu/aligned_pass_kernels.h"
#include "emu/device.h"
#include "emu/format.h"
#include "ps11/assembler.h"
#include "ps11/validator.h"
#include "aligned_cases.h"
#include "aligned_rows_util.h"
#include "simd_levels.h"

using namespace emu;

using namespace emu;

using namespace alignedcases;
using namespace alignedrows;

TEST_CASE("aligned pass: the fx8 store kernels write the rule's words and nothing past the count", "[draw][aligned]") {
    // storeRow at every level with vector kernels, against the rule: each channel's byte at its
    // b g r a position, orMask or-ed in, or (additive) the saturating byte sum with what is under
    // it (the target's own bytes, or another row's: a copy into the target not made yet,
    // RowSource); lengths around whole groups of 16 and 32, so every tail is masked; the
    // target's words past the count keep their bytes.
    testutil::forEachSimdLevel([](ps11::SimdLevel level) {
        const AlignedKernels* k = alignedKernels(level);
        if (!k) return;
        std::mt19937 rng(20261130);
        for (const bool additive : {false, true})
            for (const uint32_t orMask : {0u, 0xff000000u})
                for (const int n : {1, 7, 15, 16, 17, 31, 32, 33, 47, 48, 63, 64, 65, 100, 255, 256}) {
                    INFO("n " << n << (additive ? " additive" : "") << " or " << orMask);
                    alignas(64) int16_t planes[4][ps11::kMaxSpan];
                    for (auto& plane : planes)
                        for (int16_t& v : plane) v = int16_t(rng() % 256);
                    std::vector<uint8_t> dst(4 * size_t(n) + 64), other(4 * size_t(n)), expect;
                    for (uint8_t& b : dst) b = uint8_t(rng());
                    for (uint8_t& b : other) b = uint8_t(rng());
                    const bool fromOther = rng() % 2;
                    const uint8_t* const base = fromOther ? other.data() : dst.data();
                    INFO((fromOther ? "under: another row" : "under: the target's"));
                    expect = dst;
                    for (int i = 0; i < n; ++i) {
                        uint32_t word = 0;
                        for (int c = 0; c < 4; ++c) {
                            const size_t at = 4 * size_t(i) + size_t(ps11::kUnorm8Byte[c]);
                            const int v = additive ? std::min(255, planes[c][i] + base[at]) : planes[c][i];
                            word |= uint32_t(v) << (8 * ps11::kUnorm8Byte[c]);
                        }
                        word |= orMask;
                        for (int b = 0; b < 4; ++b) expect[4 * size_t(i) + size_t(b)] = uint8_t(word >> (8 * b));
                    }
                    const int16_t* const r[4] = {planes[0], planes[1], planes[2], planes[3]};
                    const int done = k->storeRow(additive, r, n, orMask, base, dst.data());
                    REQUIRE(done == n);
                    CHECK(dst == expect);
                }
    });
}

TEST_CASE("aligned pass: verticalStore writes verticalBytes' words masked, stored or added, and nothing past the count",
          "[draw][aligned]") {
    // A copied magnified tap goes from its H rows to the target as words (copyTexels). At every
    // level with vector kernels, for every H-row kind at vertical weights 0, 128 and others,
    // lengths around whole groups of 16 and 32: the words are verticalBytes', each
    // (word & keep) | set, stored or (additive) added with saturation to the bytes under them —
    // the target's own, or another row's (a copy into the target not made yet, RowSource); the
    // target's words past the count keep their bytes.
    testutil::forEachSimdLevel([](ps11::SimdLevel level) {
        const AlignedKernels* k = alignedKernels(level);
        if (!k) return;
        std::mt19937 rng(20261202);
        constexpr int kMax = 300;
        std::vector<uint16_t> rows(2 * 4 * size_t(kMax + kHRowPad));
        for (const HKind kind : {HKind::A, HKind::S, HKind::H, HKind::Q})
            for (const int32_t wy : {0, 128, 16, 48, 77, 200})
                for (const bool additive : {false, true})
                    for (const int n : {1, 7, 15, 16, 17, 31, 32, 33, 47, 63, 64, 65, 255, kMax}) {
                        const uint32_t top = kind == HKind::A ? 255 : kind == HKind::S ? 510 : kind == HKind::Q ? 4080 : 65280;
                        for (uint16_t& v : rows) v = uint16_t(rng() % (top + 1));
                        const size_t stride = size_t(kMax + kHRowPad);
                        const uint16_t* h0[4];
                        const uint16_t* h1[4];
                        for (int c = 0; c < 4; ++c) {
                            h0[c] = &rows[size_t(c) * stride];
                            h1[c] = &rows[size_t(4 + c) * stride];
                        }
                        // Alpha kept or set to a constant, the X8 target's alpha set.
                        const uint32_t keep = rng() % 2 ? ~0u : 0x00ffffffu;
                        const uint32_t set = keep == ~0u ? (rng() % 2 ? 0xff000000u : 0u) : uint32_t(rng() % 256) << 24;
                        INFO("kind " << int(kind) << ", wy " << wy << ", n " << n << (additive ? ", additive" : "")
                                     << ", keep " << keep << ", set " << set);
                        std::vector<uint8_t> words(4 * size_t(n + 32));
                        k->verticalBytes(kind, h0, h1, wy, n, words.data());
                        std::vector<uint8_t> dst(4 * size_t(n) + 64), other(4 * size_t(n)), expect;
                        for (uint8_t& b : dst) b = uint8_t(rng());
                        for (uint8_t& b : other) b = uint8_t(rng());
                        const bool fromOther = rng() % 2;
                        const uint8_t* const base = fromOther ? other.data() : dst.data();
                        expect = dst;
                        for (int i = 0; i < n; ++i) {
                            uint32_t w = 0, d = 0;
                            std::memcpy(&w, &words[4 * size_t(i)], 4);
                            std::memcpy(&d, base + 4 * size_t(i), 4);
                            w = (w & keep) | set;
                            if (additive)
                                for (int b = 0; b < 4; ++b) {
                                    const uint32_t sum = std::min(255u, ((w >> (8 * b)) & 0xffu) + ((d >> (8 * b)) & 0xffu));
                                    w = (w & ~(0xffu << (8 * b))) | sum << (8 * b);
                                }
                            std::memcpy(&expect[4 * size_t(i)], &w, 4);
                        }
                        INFO((fromOther ? "under: another row" : "under: the target's"));
                        k->verticalStore(kind, h0, h1, wy, n, keep, set, additive, base, dst.data());
                        REQUIRE(dst == expect);
                    }
    });
}

TEST_CASE("aligned pass: a row under a RowSource ends as if the copy had been made first", "[draw][aligned]") {
    // SourcedRow against a model row that starts as the source: random sequences of direct
    // stores (each word from the one under it, read where base() says, then mark()), other
    // writes (materialise() first, then the word from the target's), and stores that back out
    // after base() (then written as other writes), over rows of 1 to 400 columns, with more
    // disjoint spans than the row keeps (32) now and then; the rest of the row at the end.
    std::mt19937 rng(20261206);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    for (int i = 0; i < 3000; ++i) {
        const int w = uni(1, 400);
        const size_t words = static_cast<size_t>(w);
        std::vector<uint32_t> source(words), target(words), model(words);
        for (uint32_t& v : source) v = uint32_t(rng());
        for (uint32_t& v : target) v = uint32_t(rng());  // what the target held before the copy
        model = source;
        SourcedRow row;
        row.start(reinterpret_cast<const uint8_t*>(source.data()), reinterpret_cast<uint8_t*>(target.data()), w);
        const int ops = uni(0, 80);
        const bool narrow = uni(0, 3) == 0;  // many short, scattered writes: spans past the 32 kept
        for (int k = 0; k < ops; ++k) {
            const int x = uni(0, w - 1), n = uni(1, std::min(w - x, narrow ? 3 : w));
            const uint32_t mul = uint32_t(rng()) | 1u, add = uint32_t(rng());
            const int kind = uni(0, 2);
            INFO("case " << i << ", width " << w << ", op " << k << ": " << kind << " at " << x << " of " << n);
            if (kind == 0) {
                const uint8_t* base = row.base(x, n);
                for (int j = 0; j < n; ++j) {
                    uint32_t under = 0;
                    std::memcpy(&under, base + 4 * size_t(j), 4);
                    REQUIRE(under == model[size_t(x + j)]);
                    target[size_t(x + j)] = under * mul + add;
                }
                row.mark(x, n);
            } else {
                if (kind == 2) (void)row.base(x, n);  // (a store that did not qualify)
                row.materialise(x, n);
                for (int j = 0; j < n; ++j) {
                    REQUIRE(target[size_t(x + j)] == model[size_t(x + j)]);
                    target[size_t(x + j)] = target[size_t(x + j)] * mul + add;
                }
            }
            for (int j = 0; j < n; ++j) model[size_t(x + j)] = model[size_t(x + j)] * mul + add;
        }
        row.materialise(0, w);
        INFO("case " << i << ", width " << w);
        REQUIRE(target == model);
    }
}

TEST_CASE("aligned pass: a 4:1 reduction's pair sums straight from the texel row equal the staged combine",
          "[draw][aligned]") {
    // pairSums4 against the rule (channel sums of texels 4j, 4j + 1 and 4j + 2, 4j + 3, planes
    // r g b a) and against deinterleave + combine (step 4, weight ½, phases 0 and 2), for lengths
    // around whole groups of 16 and random bytes; nothing past texel 4n is read (the row ends
    // there, in a buffer of its own).
    const ps11::ScopedSimdLevel level(ps11::SimdLevel::Avx2);
    const AlignedKernels* k = alignedKernels(level.level());
    if (!k) return;
    std::mt19937 rng(20261129);
    for (const int n : {1, 5, 15, 16, 17, 31, 32, 48, 63, 64, 100, 480}) {
        std::vector<uint8_t> row(size_t(16) * size_t(n));
        for (uint8_t& b : row) b = uint8_t(rng());
        const size_t stride = size_t((n + kHRowPad + 15) & ~15);
        std::vector<uint16_t> even(stride * 4), odd(stride * 4);
        uint16_t* const e[4] = {&even[0], &even[stride], &even[2 * stride], &even[3 * stride]};
        uint16_t* const o[4] = {&odd[0], &odd[stride], &odd[2 * stride], &odd[3 * stride]};
        k->pairSums4(row.data(), n, e, o);
        // The staged way: 4n texels deinterleaved (with the padding combine reads), then combined.
        const size_t sstride = size_t(4 * n + kStagePad + 16);
        std::vector<uint16_t> staged(sstride * 4);
        uint16_t* const s[4] = {&staged[0], &staged[sstride], &staged[2 * sstride], &staged[3 * sstride]};
        k->deinterleave(row.data(), 4 * n, s);
        std::vector<uint16_t> ce(stride * 4), co(stride * 4);
        uint16_t* const cev[4] = {&ce[0], &ce[stride], &ce[2 * stride], &ce[3 * stride]};
        uint16_t* const cov[4] = {&co[0], &co[stride], &co[2 * stride], &co[3 * stride]};
        const uint16_t* const s0[4] = {s[0], s[1], s[2], s[3]};
        const uint16_t* const s2[4] = {s[0] + 2, s[1] + 2, s[2] + 2, s[3] + 2};
        k->combine(s0, n, 4, 128, cev);
        k->combine(s2, n, 4, 128, cov);
        for (int c = 0; c < 4; ++c)
            for (int j = 0; j < n; ++j) {
                const int b = ps11::kUnorm8Byte[c];
                INFO("n " << n << ", channel " << c << ", element " << j);
                REQUIRE(e[c][j] == row[size_t(16 * j + b)] + row[size_t(16 * j + 4 + b)]);
                REQUIRE(o[c][j] == row[size_t(16 * j + 8 + b)] + row[size_t(16 * j + 12 + b)]);
                REQUIRE(e[c][j] == cev[c][j]);
                REQUIRE(o[c][j] == cov[c][j]);
            }
    }
}

namespace {

// A w x h target over four taps of one texture `scale` times its size (random texels and target
// bytes), the blur program (weight 0.25 each), plain (blend 0) or ONE/ONE; the taps' offsets
// (in texels of the texture, from the half-pixel quad's 1:1 mapping of the block) are
// `offsets[s]`.
Case reductionCase(std::mt19937& rng, UINT w, UINT h, int scale, DWORD filter, DWORD address, DWORD blend,
                   const float (*offsets)[2]) {
    Case c = randomCase(rng);
    c.w = w, c.h = h;
    c.rtInit.resize(size_t(c.w) * c.h * 4);
    for (uint8_t& b : c.rtInit) b = uint8_t(rng());
    for (Case::Tex& t : c.tex) {
        t.w = UINT(scale) * c.w, t.h = UINT(scale) * c.h, t.format = D3DFMT_A8R8G8B8, t.bound = true;
        t.filter = filter, t.addressU = t.addressV = address;
        t.bytes.resize(size_t(t.w) * t.h * 4);
        for (uint8_t& b : t.bytes) b = uint8_t(rng());
    }
    c.oneTexture = true;
    c.program = "ps_1_1\ndef c0, 0.25, 0.25, 0.25, 0.25\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\n"
                "mad r0, t1, c0, r0\nmad r0, t2, c0, r0\nmad r0, t3, c0, r0\n";
    c.blend = blend, c.alphaTest = false, c.writeMask = 0xf, c.scissor = false;
    c.verts.clear();
    const float dx[4] = {offsets[0][0], offsets[1][0], offsets[2][0], offsets[3][0]};
    const float dy[4] = {offsets[0][1], offsets[1][1], offsets[2][1], offsets[3][1]};
    screenQuad(c, c.tex[0], dx, dy);
    return c;
}

}  // namespace

TEST_CASE("aligned pass: 4:1 reductions by weight-½ taps (a glow's sources) equal the quad path", "[draw][aligned]") {
    // The glow's first pass: four bilinear taps one texel either side of each 4x4 block's centre
    // (H rows of pair sums from the texel row, both phases at once), random texels, a target of
    // several groups of 16 and a ragged end, in fx8, plain and ONE/ONE.
    std::mt19937 rng(20261130);
    const float off[4][2] = {{-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
    for (int i = 0; i < 8; ++i) {
        const UINT w = UINT(std::uniform_int_distribution<int>(20, 90)(rng));
        const Case c = reductionCase(rng, w, 6, 4, D3DTEXF_LINEAR, D3DTADDRESS_CLAMP, DWORD(i % 2), off);
        INFO("case " << i << ": " << c.w << "x" << c.h);
        requireRowsAtEveryLevel(c, ps11::Precision::Fx8, 1 + (i & 1));
    }
}

TEST_CASE("aligned pass: point reductions by 2 to 8 (a bright pass) equal the quad path", "[draw][aligned]") {
    // A W/s x H/s target point-sampling a texture s times its size (the adaptive glare's bright
    // pass reads one scene texel in 8): four taps at different phases within each s x s block, in
    // wrap and clamp, random texels, plain and ONE/ONE, fx8 and fx12. Their H rows are of kind A at
    // a step of s, picked straight from the texel row.
    std::mt19937 rng(20261201);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    for (int i = 0; i < 12; ++i) {
        const int scale = std::array<int, 6>{2, 3, 4, 5, 7, 8}[size_t(i % 6)];
        // Each tap at the centre of texel (s·x + px, s·y + py) of its block.
        float off[4][2];
        const float half = 0.5f * float(scale) - 0.5f;  // the block's centre to its first texel's
        for (auto& p : off) p[0] = float(uni(0, scale - 1)) - half, p[1] = float(uni(0, scale - 1)) - half;
        const UINT w = UINT(uni(20, 70));
        const DWORD address = uni(0, 1) ? D3DTADDRESS_WRAP : D3DTADDRESS_CLAMP;
        const Case c = reductionCase(rng, w, 5, scale, D3DTEXF_POINT, address, DWORD(i % 2), off);
        for (const ps11::Precision precision : {ps11::Precision::Fx8, ps11::Precision::Fx12}) {
            INFO("case " << i << ": " << c.w << "x" << c.h << " from " << scale << " times that, "
                         << ps11::precisionName(precision));
            requireRowsAtEveryLevel(c, precision, 1 + (i & 1));
        }
    }
}

TEST_CASE("aligned pass: a point reduction's H rows are picked from the texel row, with no staged row",
          "[draw][aligned]") {
    // Below the device: `mov r0, t0` over a 40x4 target from a texture 8 times as wide and
    // 4 times as high, point-sampled at texel (8x + 5, 4y + 1): every pixel is that texel's bytes,
    // and the vector path built one H row per pixel row without deinterleaving a whole texel row.
    const int w = 40, h = 4, sx = 8, sy = 4;
    const std::unique_ptr<ps11::Executor> exec = copyExecutor(ps11::Precision::Fx8);
    std::vector<uint8_t> texels(size_t(w * sx) * size_t(h * sy) * 4);
    std::mt19937 rng(7);
    for (uint8_t& b : texels) b = uint8_t(rng());
    Image target = blankTarget(w, h);
    TriangleSetup setups[2];
    uint64_t used = 0;
    // Pixel x's u lands on texel 8x + 3.5 + du·8: du = 1.5 / 8 gives 8x + 5 (and v: 4y + 1).
    quadSetups(w, h, 1.5f / float(sx), -0.5f / float(sy), setups, used);
    AlignedDraw d;
    AlignedTriangle at[2];
    tapDraw(*exec, target, used, texels, uint32_t(w * sx), uint32_t(h * sy), false, d);
    for (int t = 0; t < 2; ++t) REQUIRE(prepareAlignedTriangle(d, setups[t], at[t]));
    const AlignedTriangle* tp[2] = {&at[0], &at[1]};
    const TriangleSetup* sp[2] = {&setups[0], &setups[1]};
    auto scratch = std::make_unique<AlignedScratch>();
    AlignedStats stats;
    drawAlignedRows(d, tp, sp, 2, 0, h, *scratch, stats);
    int wrong = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c)
                wrong += target.bytes[(size_t(y) * w + size_t(x)) * 4 + size_t(c)] !=
                         texels[((size_t(sy * y + 1) * size_t(w * sx)) + size_t(sx * x + 5)) * 4 + size_t(c)];
    CHECK(wrong == 0);
    if (alignedKernels(ps11::simdLevel())) {
        REQUIRE(at[0].configs.size() == 1);
        CHECK(at[0].configs[0].step == sx);
        CHECK(at[0].configs[0].wx == 0);
        CHECK(scratch->hrows.staged == 0);
        CHECK(scratch->hrows.built == uint64_t(h));
    }
}

TEST_CASE("aligned pass: chains of products that pass the range's top are clamped after each op", "[draw][aligned]") {
    // The weighted blur's mul and three mads (one kernel for the chain: exec::FastKernels::chain)
    // with weights whose sum passes 1, over bright random texels: the running sum meets hi and
    // is clamped after each op, as the quad path's per-op arithmetic does. POINT taps at whole
    // texels (direct runs) and bilinear ones between texels.
    std::mt19937 rng(20261131);
    auto real = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
    for (int i = 0; i < 8; ++i) {
        Case c = randomCase(rng);
        c.w = 70, c.h = 5;
        c.rtInit.assign(size_t(c.w) * c.h * 4, 0);
        for (Case::Tex& t : c.tex) {
            t.w = c.w, t.h = c.h, t.format = D3DFMT_A8R8G8B8, t.bound = true;
            t.filter = i % 2 ? D3DTEXF_LINEAR : D3DTEXF_POINT;
            t.addressU = t.addressV = D3DTADDRESS_CLAMP;
            t.bytes.resize(size_t(t.w) * t.h * 4);
            for (uint8_t& b : t.bytes) b = uint8_t(std::uniform_int_distribution<int>(100, 255)(rng));
        }
        c.oneTexture = true;
        // (The sub after the chain shows its clamp: the store would clamp an unclamped sum anyway.)
        c.program = "ps_1_1\ndef c4, 0.5, 0.5, 0.5, 0.5\ntex t0\ntex t1\ntex t2\ntex t3\nmul r0, t0, c0\n"
                    "mad r0, t1, c1, r0\nmad r0, t2, c2, r0\nmad r0, t3, c3, r0\nsub r0, r0, c4\n";
        for (auto& k : c.consts)
            for (float& v : k) v = real(0.2f, 1.0f);
        c.blend = 0, c.alphaTest = false, c.writeMask = 0xf, c.scissor = false, c.fog = false, c.depth = false;
        c.verts.clear();
        const float xs[4] = {-0.5f, float(c.w) - 0.5f, float(c.w) - 0.5f, -0.5f};
        const float ys[4] = {-0.5f, -0.5f, float(c.h) - 0.5f, float(c.h) - 0.5f};
        const float shift = i % 2 ? 0.5f : 1.0f;
        for (int k : {0, 1, 2, 0, 2, 3}) {
            Vtx v{xs[k], ys[k], 0.5f, 1.0f, 0xffffffff, 0xff000000u, {}};
            for (int s = 0; s < 4; ++s) {
                v.uv[s][0] = ((k == 1 || k == 2) ? 1.0f : 0.0f) + (float(s) - 1.5f) * shift / float(c.w);
                v.uv[s][1] = k >= 2 ? 1.0f : 0.0f;
            }
            c.verts.push_back(v);
        }
        DeviceOptions quadOpt, rowOpt;
        quadOpt.software.alignedPasses = false;
        rowOpt.software.skipTiles = false;
        Device quadDev(quadOpt), rowDev(rowOpt);
        DrawStats qs, rs;
        const std::vector<uint8_t> expected = drawCase(quadDev, c, qs);
        INFO("case " << i);
        REQUIRE(drawCase(rowDev, c, rs) == expected);
        CHECK(rs.pixelsShaded == rs.pixelsCovered);
        // The clamp mattered: the sum reached 1, less 0.5 (the byte 127 or 128).
        CHECK(std::count_if(expected.begin(), expected.end(), [](uint8_t b) { return b == 127 || b == 128; }) > 100);
    }
}
