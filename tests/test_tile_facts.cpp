// Tile facts known without a scan (emu/tile_facts.h, ps11::uniformTileRange): a texture cleared
// whole and then drawn into in places gives, from one scanned tile and the tiles the draws
// reached, exactly the facts a scan of every tile gives; any other write forgets them.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "emu/device.h"
#include "emu/fullscreen.h"
#include "emu/tile_facts.h"
#include "ps11/texture.h"
#include "ps11/texture_tiles.h"
#include "texel_tiles_util.h"

using namespace ps11;

namespace {

bool sameTile(const TexelRange& a, const TexelRange& b) {
    return std::memcmp(a.lo.data(), b.lo.data(), sizeof a.lo) == 0 &&
           std::memcmp(a.hi.data(), b.hi.data(), sizeof a.hi) == 0 && a.nan == b.nan && a.negZero == b.negZero;
}

// The facts of `t` by a scan of every tile, and from `stale` by the uniform path (in two halves of
// tile rows, as workers fill them); every tile must be the same.
void checkUniformPath(const Texture& t, const std::vector<uint8_t>& stale) {
    TexelTiles full, known;
    prepareTexelTiles(t, full);
    scanTexelTiles(t, full, 0, full.tilesY);
    prepareTexelTiles(t, known);
    REQUIRE(stale.size() == known.tiles.size());
    TexelRange uniform;
    const bool some = uniformTileRange(t, known, stale, uniform);
    // Every tile stale: nothing to take the uniform value from.
    REQUIRE(some == (std::count(stale.begin(), stale.end(), uint8_t(0)) > 0));
    if (!some) return;
    fillUniformTiles(t, known, stale, uniform, 0, known.tilesY / 2);
    fillUniformTiles(t, known, stale, uniform, known.tilesY / 2, known.tilesY);
    for (size_t i = 0; i < full.tiles.size(); ++i) {
        INFO("tile " << i % full.tilesX << "," << i / full.tilesX << " of " << full.tilesX << "x" << full.tilesY
                     << (stale[i] ? " (stale)" : ""));
        CHECK(sameTile(known.tiles[i], full.tiles[i]));
    }
}

}  // namespace

TEST_CASE("tile facts: one value everywhere but the stale tiles gives the full scan's facts", "[tiles]") {
    // A8R8G8B8 (bytes) and A32B32G32R32F (floats, with NaN, ±0 and infinities among the written
    // texels and the background), sizes with partial edge tiles; blocks of texels written over
    // the background, their tiles flagged, and some clean tiles flagged too (a draw's bounding
    // box reaches further than its pixels).
    std::mt19937 rng(20261130);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    const float inf = std::numeric_limits<float>::infinity();
    const float specials[] = {0.0f, -0.0f, 1.0f, 0.25f, std::nanf(""), inf, -inf, -3.5f};
    for (int i = 0; i < 120; ++i) {
        const bool unorm8 = i % 2 == 0;
        const uint32_t w = uint32_t(uni(1, 300)), h = uint32_t(uni(1, 300));
        std::vector<uint8_t> bytes;
        std::vector<float> floats;
        std::array<uint8_t, 4> bg8{};
        std::array<float, 4> bgf{};
        for (int c = 0; c < 4; ++c) bg8[size_t(c)] = uint8_t(rng()), bgf[size_t(c)] = specials[rng() % 8];
        if (unorm8) {
            bytes.resize(size_t(w) * h * 4);
            for (size_t k = 0; k < bytes.size(); ++k) bytes[k] = bg8[k % 4];
        } else {
            floats.resize(size_t(w) * h * 4);
            for (size_t k = 0; k < floats.size(); ++k) floats[k] = bgf[k % 4];
        }
        const uint32_t side = texelTileSide(w, h), tilesX = (w + side - 1) / side, tilesY = (h + side - 1) / side;
        std::vector<uint8_t> stale(size_t(tilesX) * tilesY, 0);
        const int blocks = uni(0, 6);
        for (int b = 0; b < blocks; ++b) {
            const uint32_t x0 = uint32_t(uni(0, int(w) - 1)), y0 = uint32_t(uni(0, int(h) - 1));
            const uint32_t x1 = std::min(w, x0 + uint32_t(uni(1, 40))), y1 = std::min(h, y0 + uint32_t(uni(1, 40)));
            for (uint32_t y = y0; y < y1; ++y)
                for (uint32_t x = x0; x < x1; ++x)
                    for (int c = 0; c < 4; ++c) {
                        const size_t k = (size_t(y) * w + x) * 4 + size_t(c);
                        if (rng() % 3 == 0) continue;  // some texels keep the background
                        if (unorm8)
                            bytes[k] = uint8_t(rng());
                        else
                            floats[k] = rng() % 4 == 0 ? specials[rng() % 8]
                                                       : float(std::ldexp(double(int64_t(rng() % 2001) - 1000), -8));
                    }
            for (uint32_t ty = y0 / side; ty <= (y1 - 1) / side; ++ty)
                for (uint32_t tx = x0 / side; tx <= (x1 - 1) / side; ++tx) stale[size_t(ty) * tilesX + tx] = 1;
        }
        for (int k = uni(0, 3); k > 0; --k) stale[rng() % stale.size()] = 1;
        if (i % 17 == 0) std::fill(stale.begin(), stale.end(), uint8_t(1));
        const Texture t = tiletest::levelTexture(unorm8, w, h, bytes, floats);
        INFO((unorm8 ? "A8R8G8B8 " : "A32B32G32R32F ") << w << "x" << h << ", " << blocks << " blocks");
        checkUniformPath(t, stale);
    }
}

TEST_CASE("tile facts: a target cleared whole, then drawn into, is known but where the draws reached",
          "[tiles][device]") {
    // Render-target textures of 8-bit and float formats, cleared whole to a random colour, then
    // random triangles (anywhere, partly outside, thin) drawn replacing or ONE/ONE. Each sampled
    // view must carry the facts, and the facts from them must be the full scan's; a lock, a
    // StretchRect (of part or of the whole) or a clear of part of the target must forget them.
    using namespace emu;
    std::mt19937 rng(1130);
    int checkedDraws = 0;
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    auto real = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
    for (int i = 0; i < 40; ++i) {
        DeviceOptions o;
        o.software.threads = 2;
        Device dev(o);
        const D3DFORMAT fmt = i % 2 ? D3DFMT_A32B32G32R32F : D3DFMT_A8R8G8B8;
        const UINT w = UINT(uni(8, 400)), h = UINT(uni(8, 300));
        Handle tex{}, level{}, shader{}, other{};
        REQUIRE(dev.CreateTexture(w, h, 1, D3DUSAGE_RENDERTARGET, fmt, D3DPOOL_DEFAULT, &tex) == D3D_OK);
        REQUIRE(dev.GetSurfaceLevel(tex, 0, &level) == D3D_OK);
        REQUIRE(dev.CreateRenderTarget(w, h, fmt, 1, &other) == D3D_OK);
        const std::string c0 = std::to_string(real(0, 1)) + ", " + std::to_string(real(0, 1)) + ", " +
                               std::to_string(real(0, 1)) + ", " + std::to_string(real(0, 1));
        REQUIRE(dev.CreatePixelShaderFromText("ps_1_1\ndef c0, " + c0 + "\nmov r0, c0\n", &shader) == D3D_OK);
        REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, D3DCOLOR(rng()), 1.0f, 0) == D3D_OK);
        std::shared_ptr<const Texture> t = dev.sampledTexture(tex);
        REQUIRE(t);
        std::shared_ptr<const std::vector<uint8_t>> stale = t->uniformTiles();
        REQUIRE(stale);
        CHECK(std::count(stale->begin(), stale->end(), uint8_t(1)) == 0);
        checkUniformPath(*t, *stale);
        // Draws, checked after each.
        REQUIRE(dev.SetPixelShader(shader) == D3D_OK);
        REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
        for (int d = uni(1, 4); d > 0; --d) {
            REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, uni(0, 1)) == D3D_OK);
            REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
            REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE) == D3D_OK);
            std::vector<QuadVertex> v;
            for (int tri = uni(1, 5); tri > 0; --tri) {
                const double cx = real(-20, double(w) + 20), cy = real(-20, double(h) + 20), r = real(0.2, 60);
                for (int k = 0; k < 3; ++k) {
                    QuadVertex q{};
                    q.x = float(cx + real(-r, r)), q.y = float(cy + real(-r, r)), q.z = 0.5f, q.rhw = 1;
                    v.push_back(q);
                }
            }
            REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, UINT(v.size() / 3), v.data(), sizeof(QuadVertex)) ==
                    D3D_OK);
            t = dev.sampledTexture(tex);
            REQUIRE(t);
            // (Null once the triangles have reached every tile: nothing known is left.)
            stale = t->uniformTiles();
            if (!stale) break;
            INFO((fmt == D3DFMT_A8R8G8B8 ? "A8R8G8B8 " : "A32B32G32R32F ") << w << "x" << h);
            checkUniformPath(*t, *stale);
            ++checkedDraws;
        }
        // A draw over the whole target leaves nothing known.
        if (i % 4 == 0) {
            REQUIRE(drawFullscreenQuad(dev) == D3D_OK);
            t = dev.sampledTexture(tex);
            REQUIRE(t);
            CHECK_FALSE(t->uniformTiles());
            REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, D3DCOLOR(rng()), 1.0f, 0) == D3D_OK);
        }
        // Writes of other kinds forget the facts; a whole clear knows them again.
        const int other_write = i % 3;
        if (other_write == 0) {
            const RECT part{0, 0, LONG(w / 2 + 1), LONG(h / 2 + 1)};
            REQUIRE(dev.StretchRect(other, &part, level, &part, D3DTEXF_POINT) == D3D_OK);
        } else if (other_write == 1) {
            REQUIRE(dev.StretchRect(other, nullptr, level, nullptr, D3DTEXF_POINT) == D3D_OK);
        } else {
            const D3DRECT part{0, 0, LONG(w / 2), LONG(h)};
            REQUIRE(dev.Clear(1, &part, D3DCLEAR_TARGET, D3DCOLOR(rng()), 1.0f, 0) == D3D_OK);
        }
        t = dev.sampledTexture(tex);
        REQUIRE(t);
        CHECK_FALSE(t->uniformTiles());
        REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, D3DCOLOR(rng()), 1.0f, 0) == D3D_OK);
        t = dev.sampledTexture(tex);
        REQUIRE(t);
        REQUIRE(t->uniformTiles());
        checkUniformPath(*t, *t->uniformTiles());
    }
    CHECK(checkedDraws > 40);
}

TEST_CASE("tile facts: the boxes kept while a renderer assembles give the tiles a second assembly gives",
          "[tiles]") {
    // A call of small random triangles (some partly off the target) whose assemble counts its
    // calls: marked from the boxes the watched assemble kept, the tiles equal those marked by
    // assembling again, and nothing is assembled a second time. A renderer that leaves
    // primitives unassembled gets the second assembly. A NaN vertex marks every tile.
    emu::Image target;
    target.width = 300, target.height = 200;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> corner(-20.0, 300.0), size(0.0, 25.0);
    std::vector<emu::ScreenTriangle> all(40);
    for (emu::ScreenTriangle& t : all) {
        const double x = corner(rng), y = corner(rng) * 2 / 3;
        for (emu::ScreenVertex& v : t.v) v.x = x + size(rng), v.y = y + size(rng);
    }
    emu::DrawCall call;
    call.primitiveCount = uint32_t(all.size());
    call.clip = emu::ClipRect{0, 0, 300, 200};
    int assembles = 0;
    call.assemble = [&](uint32_t first, uint32_t count, std::vector<emu::ScreenTriangle>& out) {
        ++assembles;
        out.insert(out.end(), all.begin() + first, all.begin() + first + count);
    };
    const std::vector<uint8_t> stale(emu::uniformTileCount(target), 0);
    const auto again = emu::markDrawnTiles(call, target, stale);
    REQUIRE(assembles > 0);
    REQUIRE(again);  // (some tiles marked, some not)
    const auto marked = std::count(again->begin(), again->end(), uint8_t(1));
    CHECK(marked > 0);
    CHECK(size_t(marked) < again->size());
    for (const uint32_t upTo : {40u, 39u}) {
        assembles = 0;
        std::shared_ptr<const std::vector<uint8_t>> kept;
        {
            emu::AssembledBoxes boxes(call);
            std::vector<emu::ScreenTriangle> tris;
            for (uint32_t first = 0; first < upTo; first += 16) call.assemble(first, std::min(16u, upTo - first), tris);
            CHECK(boxes.complete() == (upTo == 40));
            const int drawn = assembles;
            kept = emu::markDrawnTiles(call, target, stale, &boxes);
            CHECK((assembles == drawn) == (upTo == 40));
        }
        REQUIRE(bool(again) == bool(kept));
        if (again) CHECK(*again == *kept);
        // The call's own assemble is back.
        assembles = 0;
        std::vector<emu::ScreenTriangle> tris;
        call.assemble(0, 1, tris);
        CHECK(assembles == 1);
    }
    all[17].v[2].y = std::numeric_limits<double>::quiet_NaN();
    emu::AssembledBoxes boxes(call);
    std::vector<emu::ScreenTriangle> tris;
    call.assemble(0, 40, tris);
    CHECK_FALSE(emu::markDrawnTiles(call, target, stale, &boxes));  // every tile: nothing known
}
