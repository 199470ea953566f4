// End-to-end draws through emu::Device::DrawPrimitiveUP: pixel shaders over the half-pixel 1:1
// quad (colour, an exact texture copy, a 4-tap bilinear blur checked against the fx8 arithmetic
// of docs/precision.md computed here with integers), 1 vs 2 threads, statistics, and every error
// path (its code, and nothing changed).
#include <catch2/catch.hpp>

#include <cstring>
#include <random>
#include <vector>

#include "emu/device.h"

using namespace emu;

namespace {

struct QuadVertex {
    float x, y, z, rhw;
    DWORD diffuse;
    float uv[4][2];
};
constexpr DWORD kQuadFvf = D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_TEX4;

// The 1:1 quad of D3D9 post-processing over pixels [0, w) × [0, h): corners at −0.5, texture
// coordinates 0..1 on every set, plus a per-set offset in texels of a w × h texture.
std::vector<QuadVertex> quad(int w, int h, DWORD diffuse, const float (*offsets)[2] = nullptr) {
    const float xs[4] = {-0.5f, w - 0.5f, w - 0.5f, -0.5f};
    const float ys[4] = {-0.5f, -0.5f, h - 0.5f, h - 0.5f};
    const float us[4] = {0, 1, 1, 0};
    const float vs[4] = {0, 0, 1, 1};
    std::vector<QuadVertex> v;
    for (int k : {0, 1, 2, 0, 2, 3}) {
        QuadVertex q{xs[k], ys[k], 0.0f, 1.0f, diffuse, {}};
        for (int s = 0; s < 4; ++s) {
            q.uv[s][0] = us[k] + (offsets ? offsets[s][0] / float(w) : 0.0f);
            q.uv[s][1] = vs[k] + (offsets ? offsets[s][1] / float(h) : 0.0f);
        }
        v.push_back(q);
    }
    return v;
}

Handle target(Device& dev, UINT w, UINT h, DWORD fill = 0x11223344) {
    Handle rt{};
    REQUIRE(dev.CreateRenderTarget(w, h, D3DFMT_A8R8G8B8, 1, &rt) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, fill, 1.0f, 0) == D3D_OK);
    return rt;
}

std::vector<uint32_t> readTarget(Device& dev, Handle rt, UINT w, UINT h) {
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(rt, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    std::vector<uint32_t> px(size_t(w) * h);
    for (UINT y = 0; y < h; ++y) std::memcpy(&px[y * w], static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch, 4 * w);
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);
    return px;
}

Handle randomTexture(Device& dev, UINT w, UINT h, std::vector<uint32_t>& texels, uint32_t seed) {
    Handle tex{};
    REQUIRE(dev.CreateTexture(w, h, 1, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    std::mt19937 rng(seed);
    texels.resize(size_t(w) * h);
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < h; ++y)
        for (UINT x = 0; x < w; ++x) {
            texels[y * w + x] = rng();
            std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + 4 * x, &texels[y * w + x], 4);
        }
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);
    return tex;
}

uint32_t channel(uint32_t argb, int c) {  // c: 0 r, 1 g, 2 b, 3 a
    static const int shift[4] = {16, 8, 0, 24};
    return (argb >> shift[c]) & 0xff;
}

// round_half_even(p / q) for p >= 0, q > 0.
int64_t rhe(int64_t p, int64_t q) {
    const int64_t n = p / q, r = p % q;
    if (2 * r > q || (2 * r == q && (n & 1))) return n + 1;
    return n;
}

Handle shader(Device& dev, const char* text) {
    Handle ps{};
    REQUIRE(dev.CreatePixelShaderFromText(text, &ps) == D3D_OK);
    REQUIRE(dev.SetPixelShader(ps) == D3D_OK);
    return ps;
}

}  // namespace

TEST_CASE("draw: mov r0, v0 fills exactly the quad's pixels with the diffuse colour", "[draw]") {
    Device dev;
    const UINT W = 37, H = 23;
    Handle rt = target(dev, W, H);
    shader(dev, "ps_1_1\nmov r0, v0\n");
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    // A rect [5, 30) × [3, 20) through the half-pixel corners.
    std::vector<QuadVertex> v = quad(W, H, 0x80c0ff10);
    for (QuadVertex& q : v) {
        q.x = q.x < 0 ? 4.5f : 29.5f;
        q.y = q.y < 0 ? 2.5f : 19.5f;
    }
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
    const auto px = readTarget(dev, rt, W, H);
    for (UINT y = 0; y < H; ++y)
        for (UINT x = 0; x < W; ++x) {
            const bool in = x >= 5 && x < 30 && y >= 3 && y < 20;
            INFO(x << "," << y);
            CHECK(px[y * W + x] == (in ? 0x80c0ff10u : 0x11223344u));
        }
    const DrawStats& st = dev.lastDrawStats();
    CHECK(st.pixelsCovered == 25 * 17);
    CHECK(st.pixelsWritten == 25 * 17);
    CHECK(st.triangles == 2);
    CHECK(st.trianglesDrawn == 2);
}

// A 130×40 quad squaring a random texture, drawn again and again: which draws decided tiles.
// Untimed (SoftwareRendererOptions::timeTiles): the schedule follows the share of tiles saved.
struct RepeatedDraw {
    static constexpr UINT W = 130, H = 40;
    static DeviceOptions untimed() {
        DeviceOptions o;
        o.software.timeTiles = false;
        return o;
    }
    Device dev;
    Handle tex{};
    std::vector<QuadVertex> v = quad(W, H, 0xffffffff);
    explicit RepeatedDraw(const DeviceOptions& o = untimed()) : dev(o) {
        (void)target(dev, W, H);
        std::vector<uint32_t> texels;
        tex = randomTexture(dev, W, H, texels, 11);
        REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
        shader(dev, "ps_1_1\ntex t0\nmul r0, t0, t0\n");
        REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    }
    // Draws numbered [first, last); returns those whose tiles were decided.
    std::vector<int> decided(int first, int last) {
        std::vector<int> out;
        for (int i = first; i < last; ++i) {
            REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
            const DrawStats& st = dev.lastDrawStats();
            CHECK(st.pixelsCovered == W * H);
            if (st.tilesShaded + st.tilesFilled + st.tilesCopied + st.tilesSkipped) out.push_back(i);
        }
        return out;
    }
};

TEST_CASE("draw: tiles of a program that needed shading are decided again after 4, 8, 16, 32 draws", "[draw][skip]") {
    // Deciding a tile costs about a microsecond: a program whose tiles mostly needed shading is
    // shaded without deciding, and tried again on its fourth draw after, then after twice as many
    // each time it still did not pay, up to 32 (docs/device.md "Tile skipping"). The bytes are
    // the same either way.
    RepeatedDraw r;
    CHECK(r.decided(0, 100) == std::vector<int>{0, 4, 12, 28, 60, 92});
}

TEST_CASE("draw: a program whose tiles start to pay is decided on every draw again", "[draw][skip]") {
    // Tiles of a random texture need shading; once the texture is black every tile is filled,
    // and the draw after the next decision decides again (the wait is reset).
    RepeatedDraw r;
    CHECK(r.decided(0, 13) == std::vector<int>{0, 4, 12});  // waiting 16 draws now
    D3DLOCKED_RECT lr;
    REQUIRE(r.dev.LockRect(r.tex, 0, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < RepeatedDraw::H; ++y)
        std::memset(static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch), 0, 4 * RepeatedDraw::W);
    REQUIRE(r.dev.UnlockRect(r.tex, 0) == D3D_OK);
    CHECK(r.decided(13, 33) == std::vector<int>{28, 29, 30, 31, 32});
}

TEST_CASE("draw: timed, a program whose tiles pay is drawn undecided once after its second decided draw",
          "[draw][skip]") {
    // Timing needs both times: the first two draws decide (every tile of a black texture fills:
    // it pays by the share of tiles; the first is not timed), the third is timed undecided;
    // which draws decide after that follows the two times.
    RepeatedDraw r(DeviceOptions{});
    REQUIRE(r.dev.options().software.timeTiles);
    D3DLOCKED_RECT lr;
    REQUIRE(r.dev.LockRect(r.tex, 0, &lr, nullptr, 0) == D3D_OK);
    for (UINT y = 0; y < RepeatedDraw::H; ++y)
        std::memset(static_cast<uint8_t*>(lr.pBits) + size_t(y) * size_t(lr.Pitch), 0, 4 * RepeatedDraw::W);
    REQUIRE(r.dev.UnlockRect(r.tex, 0) == D3D_OK);
    CHECK(r.decided(0, 3) == std::vector<int>{0, 1});
}

TEST_CASE("draw: tex t0 over the 1:1 quad copies the texture exactly (point and bilinear)", "[draw]") {
    for (DWORD filter : {DWORD(D3DTEXF_POINT), DWORD(D3DTEXF_LINEAR)}) {
        // Every pixel shaded: the texel times a white diffuse (`mov r0, t0` would be drawn as the
        // copy it is whatever it reads, without running the program: TileSkipper::anyData).
        DeviceOptions opt;
        opt.software.skipTiles = false;
        Device dev(opt);
        const UINT W = 67, H = 41;
        Handle rt = target(dev, W, H);
        std::vector<uint32_t> texels;
        Handle tex = randomTexture(dev, W, H, texels, 7);
        REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
        REQUIRE(dev.SetSamplerState(0, D3DSAMP_MINFILTER, filter) == D3D_OK);
        REQUIRE(dev.SetSamplerState(0, D3DSAMP_MAGFILTER, filter) == D3D_OK);
        shader(dev, "ps_1_1\ntex t0\nmul r0, t0, v0\n");
        REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
        auto v = quad(W, H, 0xffffffff);
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
        CHECK(readTarget(dev, rt, W, H) == texels);
        const DrawStats& st = dev.lastDrawStats();
        CHECK(st.pixelsCovered == W * H);
        // Instructions: tex + mul per shaded lane; one texel per point lookup, four per bilinear.
        CHECK(st.instructions == 2 * st.pixelsShaded);
        CHECK(st.texelsFetched == st.pixelsShaded * (filter == D3DTEXF_LINEAR ? 4 : 1));
        // A second draw counts its own fetches only (the workers' samplers persist between draws).
        const uint64_t first = st.texelsFetched;
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
        CHECK(dev.lastDrawStats().texelsFetched == first);
        CHECK(dev.totalDrawStats().texelsFetched == 2 * first);
    }
}

TEST_CASE("draw: the 4-tap bilinear blur equals the fx8 arithmetic of docs/precision.md", "[draw]") {
    Device dev;
    const UINT W = 48, H = 30;
    Handle rt = target(dev, W, H);
    std::vector<uint32_t> texels;
    Handle tex = randomTexture(dev, W, H, texels, 99);
    for (DWORD s = 0; s < 4; ++s) {
        REQUIRE(dev.SetTexture(s, tex) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_MINFILTER, D3DTEXF_LINEAR) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_ADDRESSU, D3DTADDRESS_CLAMP) == D3D_OK);
        REQUIRE(dev.SetSamplerState(s, D3DSAMP_ADDRESSV, D3DTADDRESS_CLAMP) == D3D_OK);
    }
    shader(dev,
           "ps_1_1\ntex t0\ntex t1\ntex t2\ntex t3\n"
           "mul r0, t0, c0\nmad r0, t1, c0, r0\nmad r0, t2, c0, r0\nmad r0, t3, c0, r0\n");
    const float c0[4] = {0.25f, 0.25f, 0.25f, 0.25f};
    REQUIRE(dev.SetPixelShaderConstantF(0, c0, 1) == D3D_OK);
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    const float off[4][2] = {{0.25f, 0.25f}, {-0.25f, 0.25f}, {0.25f, -0.25f}, {-0.25f, -0.25f}};
    auto v = quad(W, H, 0xffffffff, off);
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
    const auto px = readTarget(dev, rt, W, H);

    // Expected: the constant 0.25 on the grid is round(0.25·255) = 64 (63.75 rounds up).
    const int64_t cn = 64;
    auto texel = [&](int x, int y, int c) {
        x = std::clamp(x, 0, int(W) - 1);
        y = std::clamp(y, 0, int(H) - 1);
        return int64_t(channel(texels[size_t(y) * W + size_t(x)], c));
    };
    // Tap at texel offset (dx, dy) = ±0.25: texel space x + dx; i0 = floor, weight round(f·256):
    // +0.25 → i0 = x, w = 64; −0.25 → i0 = x − 1, w = 192. Sum exact, rounded once to the grid.
    auto tap = [&](int x, int y, int s, int c) {
        const bool px_ = off[s][0] > 0, py_ = off[s][1] > 0;
        const int i0 = px_ ? x : x - 1, j0 = py_ ? y : y - 1;
        const int64_t wx = px_ ? 64 : 192, wy = py_ ? 64 : 192;
        const int64_t sum = (256 - wx) * (256 - wy) * texel(i0, j0, c) + wx * (256 - wy) * texel(i0 + 1, j0, c) +
                            (256 - wx) * wy * texel(i0, j0 + 1, c) + wx * wy * texel(i0 + 1, j0 + 1, c);
        return rhe(sum, 65536);
    };
    int mismatches = 0;
    for (UINT y = 0; y < H; ++y)
        for (UINT x = 0; x < W; ++x)
            for (int c = 0; c < 4; ++c) {
                // mul: (2n)(2c)/(4G²) → n·c/G rounded; mad: (n·c + G·r)/G rounded (all non-negative).
                int64_t r = rhe(tap(int(x), int(y), 0, c) * cn, 255);
                for (int s = 1; s < 4; ++s) r = rhe(tap(int(x), int(y), s, c) * cn + 255 * r, 255);
                if (int64_t(channel(px[y * W + x], c)) != r) ++mismatches;
            }
    CHECK(mismatches == 0);
    const DrawStats& st = dev.lastDrawStats();
    CHECK(st.texelsFetched == 16 * st.pixelsShaded);
    CHECK(st.instructions == 8 * st.pixelsShaded);
}

TEST_CASE("draw: one and two threads give identical images", "[draw]") {
    std::vector<std::vector<uint32_t>> images;
    for (int threads : {1, 2, 3}) {
        DeviceOptions o;
        o.software.threads = threads;
        Device dev(o);
        const UINT W = 150, H = 97;
        Handle rt = target(dev, W, H);
        std::vector<uint32_t> texels;
        Handle tex = randomTexture(dev, 32, 32, texels, 5);
        REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
        REQUIRE(dev.SetSamplerState(0, D3DSAMP_MINFILTER, D3DTEXF_LINEAR) == D3D_OK);
        REQUIRE(dev.SetSamplerState(0, D3DSAMP_MAGFILTER, D3DTEXF_LINEAR) == D3D_OK);
        REQUIRE(dev.SetSamplerState(0, D3DSAMP_MIPFILTER, D3DTEXF_POINT) == D3D_OK);
        shader(dev, "ps_1_1\ntex t0\nmul r0, t0, v0\n");
        REQUIRE(dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_DIFFUSE | D3DFVF_TEX1) == D3D_OK);
        struct V {
            float x, y, z, rhw;
            DWORD c;
            float u, v;
        };
        // Overlapping perspective triangles (later ones win where they overlap).
        const V tris[6] = {{3.3f, 1.2f, 0, 1.0f, 0xffff0000, 0, 0},    {148.1f, 20.7f, 0, 0.2f, 0xff00ff00, 4, 0},
                           {20.4f, 95.9f, 0, 0.5f, 0xff0000ff, 0, 3},  {140.0f, 90.0f, 0, 1.0f, 0x80ffffff, 2, 2},
                           {10.0f, 60.0f, 0, 0.3f, 0xffffff00, -1, 1}, {100.0f, 2.0f, 0, 0.7f, 0xff00ffff, 1, -1}};
        REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, D3DCULL_NONE) == D3D_OK);
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, tris, sizeof(V)) == D3D_OK);
        images.push_back(readTarget(dev, rt, W, H));
    }
    CHECK(images[0] == images[1]);
    CHECK(images[0] == images[2]);
    CHECK(images[0] != std::vector<uint32_t>(images[0].size(), 0x11223344u));
}

TEST_CASE("draw: statistics count quads, helpers and the running total", "[draw]") {
    // The quad path (the aligned-pass path shades no helper lanes: see the last section).
    DeviceOptions opt;
    opt.software.alignedPasses = false;
    Device dev(opt);
    const UINT W = 8, H = 8;
    target(dev, W, H);
    shader(dev, "ps_1_1\nmov r0, v0\n");
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    auto v = quad(W, H, 0xffffffff);
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
    // The diagonal (−0.5, −0.5)–(7.5, 7.5) splits the 4×4 quads: each triangle touches the 6 quads
    // on its side and the 4 on the diagonal (pixel (2i+1, 2i) is above it, (2i, 2i+1) below), so
    // 20 quads = 80 lanes are shaded for 64 covered pixels.
    const DrawStats a = dev.lastDrawStats();
    CHECK(a.pixelsCovered == 64);
    CHECK(a.pixelsShaded == 80);
    CHECK(a.instructions == 80);
    CHECK(a.pixelsWritten == 64);
    CHECK(a.texelsFetched == 0);
    CHECK(a.draws == 1);
    CHECK(a.milliseconds >= 0);
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 1, v.data(), sizeof(QuadVertex)) == D3D_OK);
    const DrawStats& t = dev.totalDrawStats();
    CHECK(t.draws == 2);
    CHECK(t.triangles == 3);
    CHECK(t.pixelsCovered == 64 + dev.lastDrawStats().pixelsCovered);

    // The same draw on the aligned-pass path: rows, no helper lanes.
    DeviceOptions noSkip;
    noSkip.software.skipTiles = false;
    Device fast(noSkip);
    target(fast, W, H);
    shader(fast, "ps_1_1\nmov r0, v0\n");
    REQUIRE(fast.SetFVF(kQuadFvf) == D3D_OK);
    REQUIRE(fast.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
    CHECK(fast.lastDrawStats().pixelsCovered == 64);
    CHECK(fast.lastDrawStats().pixelsShaded == 64);
    CHECK(fast.lastDrawStats().instructions == 64);
    CHECK(fast.lastDrawStats().pixelsWritten == 64);
    CHECK(fast.lastDrawStats().tilesShaded == 0);

    // With tile skipping (the default) a constant colour fills its tiles: nothing is shaded,
    // every covered pixel is written.
    Device skip;
    target(skip, W, H);
    shader(skip, "ps_1_1\nmov r0, v0\n");
    REQUIRE(skip.SetFVF(kQuadFvf) == D3D_OK);
    REQUIRE(skip.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
    CHECK(skip.lastDrawStats().pixelsCovered == 64);
    CHECK(skip.lastDrawStats().pixelsShaded == 0);
    CHECK(skip.lastDrawStats().pixelsWritten == 64);
    CHECK(skip.lastDrawStats().tilesFilled > 0);
    CHECK(skip.lastDrawStats().tilesShaded == 0);
}

TEST_CASE("draw: clipping through World/View/Projection and the viewport", "[draw]") {
    Device dev;
    const UINT W = 40, H = 20;
    Handle rt = target(dev, W, H, 0);
    shader(dev, "ps_1_1\nmov r0, v0\n");
    REQUIRE(dev.SetFVF(D3DFVF_XYZ | D3DFVF_DIFFUSE) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, D3DCULL_NONE) == D3D_OK);
    D3DVIEWPORT9 vp{10, 4, 20, 10, 0, 1};
    REQUIRE(dev.SetViewport(&vp) == D3D_OK);
    struct V {
        float x, y, z;
        DWORD c;
    };
    // A quad far larger than the clip volume (x, y in ±5): clipped to the viewport [10, 30) × [4, 14).
    const V q[4] = {
        {-5, 5, 0.5f, 0xff00ff00}, {5, 5, 0.5f, 0xff00ff00}, {-5, -5, 0.5f, 0xff00ff00}, {5, -5, 0.5f, 0xff00ff00}};
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, q, sizeof(V)) == D3D_OK);
    const auto px = readTarget(dev, rt, W, H);
    for (UINT y = 0; y < H; ++y)
        for (UINT x = 0; x < W; ++x) {
            const bool in = x >= 10 && x < 30 && y >= 4 && y < 14;
            INFO(x << "," << y);
            CHECK(px[y * W + x] == (in ? 0xff00ff00u : 0u));
        }
    // Scissor test: only [12, 15) × [5, 7) of a second draw.
    REQUIRE(dev.Clear(0, nullptr, D3DCLEAR_TARGET, 0, 1.0f, 0) == D3D_OK);
    RECT sc{12, 5, 15, 7};
    REQUIRE(dev.SetScissorRect(&sc) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_SCISSORTESTENABLE, 1) == D3D_OK);
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, q, sizeof(V)) == D3D_OK);
    CHECK(dev.lastDrawStats().pixelsCovered == 3 * 2);
}

TEST_CASE("draw: every error path returns its code and changes nothing", "[draw]") {
    DeviceOptions o;
    o.software.threads = 1;
    Device dev(o);
    const UINT W = 8, H = 8;
    auto v = quad(W, H, 0xffffffff);
    const void* data = v.data();
    const UINT stride = sizeof(QuadVertex);

    // No render target.
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    CHECK(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4109");

    Handle rt = target(dev, W, H);
    shader(dev, "ps_1_1\nmov r0, v0\n");
    const auto before = readTarget(dev, rt, W, H);
    auto expectFail = [&](HRESULT hr, const char* code, auto&& call) {
        INFO(code);
        const DeviceState s0 = dev.state();
        CHECK(call() == hr);
        CHECK(dev.state() == s0);
        CHECK(dev.lastError().code == code);
        CHECK(dev.lastError().message.find("DrawPrimitiveUP") != std::string::npos);
        CHECK(readTarget(dev, rt, W, H) == before);
    };
    expectFail(D3DERR_INVALIDCALL, "E4113", [&] { return dev.DrawPrimitiveUP(D3DPRIMITIVETYPE(9), 2, data, stride); });
    expectFail(D3DERR_NOTAVAILABLE, "E4114", [&] { return dev.DrawPrimitiveUP(D3DPT_POINTLIST, 2, data, stride); });
    expectFail(D3DERR_NOTAVAILABLE, "E4114", [&] { return dev.DrawPrimitiveUP(D3DPT_LINELIST, 2, data, stride); });
    expectFail(D3DERR_INVALIDCALL, "E4115", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 0, data, stride); });
    expectFail(D3DERR_INVALIDCALL, "E4115",
               [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 0x100000, data, stride); });
    expectFail(D3DERR_INVALIDCALL, "E4103",
               [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, nullptr, stride); });
    expectFail(D3DERR_INVALIDCALL, "E4116", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, 0); });
    expectFail(D3DERR_INVALIDCALL, "E4116",
               [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride - 4); });
    expectFail(D3DERR_INVALIDCALL, "E4116", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, 4096); });
    REQUIRE(dev.SetFVF(0) == D3D_OK);
    expectFail(D3DERR_INVALIDCALL, "E4117", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride); });
    REQUIRE(dev.SetFVF(0x4002 | D3DFVF_DIFFUSE) == D3D_OK);  // XYZW
    expectFail(D3DERR_INVALIDCALL, "E4117", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride); });
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, 7) == D3D_OK);
    expectFail(D3DERR_INVALIDCALL, "E4119", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride); });
    REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, D3DCULL_CCW) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_FILLMODE, 2 /* WIREFRAME */) == D3D_OK);
    expectFail(D3DERR_NOTAVAILABLE, "E4120", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride); });
    REQUIRE(dev.SetRenderState(D3DRS_FILLMODE, 3) == D3D_OK);

    // Sampler and stage states of a sampled stage.
    std::vector<uint32_t> texels;
    Handle tex = randomTexture(dev, 8, 8, texels, 3);
    REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
    shader(dev, "ps_1_1\ntex t0\nmov r0, t0\n");
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MAGFILTER, 9) == D3D_OK);
    expectFail(D3DERR_UNSUPPORTEDTEXTUREFILTER, "E4123",
               [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride); });
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MAGFILTER, D3DTEXF_POINT) == D3D_OK);
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_ADDRESSU, 0) == D3D_OK);
    expectFail(D3DERR_INVALIDCALL, "E4123", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride); });
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_ADDRESSU, D3DTADDRESS_WRAP) == D3D_OK);
    REQUIRE(dev.SetTextureStageState(0, D3DTSS_TEXCOORDINDEX, D3DTSS_TCI_SPHEREMAP) == D3D_OK);
    expectFail(D3DERR_INVALIDCALL, "E4119", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride); });
    REQUIRE(dev.SetTextureStageState(0, D3DTSS_TEXCOORDINDEX, 0) == D3D_OK);
    // A locked texture.
    D3DLOCKED_RECT lr;
    REQUIRE(dev.LockRect(tex, 0, &lr, nullptr, D3DLOCK_READONLY) == D3D_OK);
    expectFail(D3DERR_INVALIDCALL, "E4106", [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride); });
    REQUIRE(dev.UnlockRect(tex, 0) == D3D_OK);

    // The render target as a texture level that is also bound for sampling.
    Handle rtTex{}, level{};
    REQUIRE(dev.CreateTexture(W, H, 1, D3DUSAGE_RENDERTARGET, D3DFMT_A8R8G8B8, D3DPOOL_DEFAULT, &rtTex) == D3D_OK);
    REQUIRE(dev.GetSurfaceLevel(rtTex, 0, &level) == D3D_OK);
    REQUIRE(dev.SetRenderTarget(0, level) == D3D_OK);
    REQUIRE(dev.SetTexture(0, rtTex) == D3D_OK);
    CHECK(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4124");
    REQUIRE(dev.SetTexture(0, tex) == D3D_OK);

    // A merger state value that is not an enumerant (emu/output_merger.h).
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, 99) == D3D_OK);
    CHECK(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4160");
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 0) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE) == D3D_OK);
    // A locked render target.
    REQUIRE(dev.SetRenderTarget(0, rt) == D3D_OK);
    REQUIRE(dev.LockRect(rt, &lr, nullptr, 0) == D3D_OK);
    CHECK(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride) == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4106");
    REQUIRE(dev.UnlockRect(rt) == D3D_OK);

    // After all the failures a valid draw works and the statistics count only it.
    REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, D3DCULL_CCW) == D3D_OK);
    CHECK(dev.totalDrawStats().draws == 0);
    CHECK(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, data, stride) == D3D_OK);
    CHECK(dev.lastError().code.empty());
    CHECK(dev.totalDrawStats().draws == 1);
}

TEST_CASE("draw: thousands of triangles keep primitive order across chunks and threads", "[draw]") {
    for (int threads : {1, 2}) {
        DeviceOptions o;
        o.software.threads = threads;
        Device dev(o);
        const int W = 100, H = 50;
        Handle rt = target(dev, W, H, 0);
        shader(dev, "ps_1_1\nmov r0, v0\n");
        REQUIRE(dev.SetFVF(D3DFVF_XYZRHW | D3DFVF_DIFFUSE) == D3D_OK);
        struct V {
            float x, y, z, rhw;
            DWORD c;
        };
        // Every pixel as its own 1×1 quad (two triangles) in colour A, then the even pixels again in
        // colour B: 5000 + 2500 quads = 15000 triangles, later ones in later chunks.
        std::vector<V> v;
        auto cell = [&](int x, int y, DWORD c) {
            const float x0 = x - 0.5f, y0 = y - 0.5f, x1 = x + 0.5f, y1 = y + 0.5f;
            for (auto [px, py] : {std::pair{x0, y0}, {x1, y0}, {x1, y1}, {x0, y0}, {x1, y1}, {x0, y1}})
                v.push_back(V{px, py, 0, 1, c});
        };
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) cell(x, y, 0xff000000u | DWORD(x << 8) | DWORD(y));
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x)
                if ((x + y) % 2 == 0) cell(x, y, 0xffff0000u | DWORD(x));
        const UINT tris = UINT(v.size() / 3);
        REQUIRE(tris == 15000);
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, tris, v.data(), sizeof(V)) == D3D_OK);
        const auto px = readTarget(dev, rt, W, H);
        int bad = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const uint32_t want =
                    (x + y) % 2 == 0 ? (0xffff0000u | uint32_t(x)) : (0xff000000u | uint32_t(x << 8) | uint32_t(y));
                bad += px[size_t(y * W + x)] != want;
            }
        CHECK(bad == 0);
        CHECK(dev.lastDrawStats().pixelsCovered == uint64_t(W * H + W * H / 2));
        CHECK(dev.lastDrawStats().trianglesDrawn == 15000);
    }
}

TEST_CASE("draw: texkill discards pixels before the merger", "[draw]") {
    Device dev;
    const UINT W = 16, H = 6;
    Handle rt = target(dev, W, H, 0xff000000);
    shader(dev, "ps_1_1\ntexkill t0\nmov r0, v0\n");
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    auto v = quad(W, H, 0xff30c050);
    // t0.u runs from −1 at the left edge to 1 at the right: u = −1 + 2(x + 0.5)/16 < 0 for x <= 7.
    for (QuadVertex& q : v) q.uv[0][0] = q.uv[0][0] * 2 - 1;
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
    const auto px = readTarget(dev, rt, W, H);
    for (UINT y = 0; y < H; ++y)
        for (UINT x = 0; x < W; ++x) CHECK(px[y * W + x] == (x >= 8 ? 0xff30c050u : 0xff000000u));
    CHECK(dev.lastDrawStats().pixelsCovered == W * H);
    CHECK(dev.lastDrawStats().pixelsWritten == 8 * H);
}

TEST_CASE("draw: fixed function MODULATE (no pixel shader) multiplies texture and diffuse", "[draw]") {
    Device dev;
    const UINT W = 20, H = 12;
    Handle rt = target(dev, W, H);
    std::vector<uint32_t> texels;
    Handle tex = randomTexture(dev, W, H, texels, 11);
    REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    // D3D9 defaults: stage 0 COLOROP MODULATE (TEXTURE, CURRENT = diffuse), ALPHAOP SELECTARG1 (TEXTURE).
    auto v = quad(W, H, 0x40806020);
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
    const auto px = readTarget(dev, rt, W, H);
    const int64_t d[3] = {0x80, 0x60, 0x20};
    int bad = 0;
    for (UINT i = 0; i < W * H; ++i) {
        // fx8 product of two grid values: round_half_even(t·d / 255); alpha is the texel's.
        for (int c = 0; c < 3; ++c)
            bad += int64_t(channel(px[i], c)) != rhe(int64_t(channel(texels[i], c)) * d[c], 255);
        bad += channel(px[i], 3) != channel(texels[i], 3);
    }
    CHECK(bad == 0);
    CHECK(dev.lastDrawStats().pixelsWritten == W * H);
}

TEST_CASE("draw: refusals of the lowering and the merger keep their codes and messages", "[draw]") {
    Device dev;
    const UINT W = 8, H = 8;
    target(dev, W, H);
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    auto v = quad(W, H, 0xff808080);
    auto draw = [&] { return dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)); };
    REQUIRE(dev.SetTextureStageState(1, D3DTSS_COLOROP, 27) == D3D_OK);
    REQUIRE(dev.SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_SELECTARG2) == D3D_OK);
    CHECK(draw() == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().hr == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4140");
    CHECK(dev.lastError().message ==
          "E4140 DrawPrimitiveUP: stage 1 D3DTSS_COLOROP: unknown texture operation 27 (D3DTOP_* is 1..26)");
    REQUIRE(dev.SetTextureStageState(1, D3DTSS_COLOROP, D3DTOP_DISABLE) == D3D_OK);
    CHECK(draw() == D3D_OK);
    CHECK(dev.lastError().code.empty());
    REQUIRE(dev.SetRenderState(D3DRS_ALPHABLENDENABLE, 1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_DESTBLEND, 99) == D3D_OK);
    CHECK(draw() == D3DERR_INVALIDCALL);
    CHECK(dev.lastError().code == "E4160");
    CHECK(dev.lastError().message == "E4160 DrawPrimitiveUP: D3DRS_DESTBLEND 99 is not a D3DBLEND value");
}

TEST_CASE("draw: the fixed-function program cache follows the state the lowering reads", "[draw]") {
    // More distinct stage setups than the cache keeps (64), each drawn twice, interleaved with a
    // setup drawn between them: every draw gives the colour of its own setup.
    Device dev;
    const UINT W = 4, H = 4;
    Handle rt = target(dev, W, H);
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    auto v = quad(W, H, 0xff000000);
    auto drawFactor = [&](DWORD factor) {
        REQUIRE(dev.SetRenderState(D3DRS_TEXTUREFACTOR, factor) == D3D_OK);
        REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
        return readTarget(dev, rt, W, H)[5];
    };
    REQUIRE(dev.SetTextureStageState(0, D3DTSS_COLOROP, D3DTOP_SELECTARG1) == D3D_OK);
    REQUIRE(dev.SetTextureStageState(0, D3DTSS_COLORARG1, D3DTA_TFACTOR) == D3D_OK);
    REQUIRE(dev.SetTextureStageState(0, D3DTSS_ALPHAOP, D3DTOP_SELECTARG1) == D3D_OK);
    REQUIRE(dev.SetTextureStageState(0, D3DTSS_ALPHAARG1, D3DTA_TFACTOR) == D3D_OK);
    int bad = 0;
    for (DWORD i = 0; i < 80; ++i) {
        const DWORD factor = 0xff000000u | (i * 3) << 16 | (255 - i) << 8 | (i * 7 & 0xff);
        bad += drawFactor(factor) != factor;
        bad += drawFactor(0xff102030u) != 0xff102030u;
        bad += drawFactor(factor) != factor;
    }
    CHECK(bad == 0);
}

TEST_CASE("draw: 2x2 quads give the sampler its mip level", "[draw]") {
    // A 64×64 texture with a full chain drawn onto 16×16 pixels: the texture coordinates change by
    // 4 texels per pixel, so the LOD is log2(4) = 2 and point mip filtering reads level 2 only.
    Device dev;
    const UINT W = 16, H = 16;
    Handle rt = target(dev, W, H);
    Handle tex{};
    REQUIRE(dev.CreateTexture(64, 64, 0, 0, D3DFMT_A8R8G8B8, D3DPOOL_MANAGED, &tex) == D3D_OK);
    const DWORD levels = dev.GetLevelCount(tex);
    REQUIRE(levels == 7);
    for (DWORD l = 0; l < levels; ++l) {
        D3DSURFACE_DESC desc;
        REQUIRE(dev.GetLevelDesc(tex, l, &desc) == D3D_OK);
        D3DLOCKED_RECT lr;
        REQUIRE(dev.LockRect(tex, l, &lr, nullptr, 0) == D3D_OK);
        const uint32_t colour = 0xff000000u | (l * 0x30u) << 16 | 0x10u * l;
        for (UINT y = 0; y < desc.Height; ++y)
            for (UINT x = 0; x < desc.Width; ++x)
                std::memcpy(static_cast<uint8_t*>(lr.pBits) + y * lr.Pitch + 4 * x, &colour, 4);
        REQUIRE(dev.UnlockRect(tex, l) == D3D_OK);
    }
    REQUIRE(dev.SetTexture(0, tex) == D3D_OK);
    REQUIRE(dev.SetSamplerState(0, D3DSAMP_MIPFILTER, D3DTEXF_POINT) == D3D_OK);
    shader(dev, "ps_1_1\ntex t0\nmov r0, t0\n");
    REQUIRE(dev.SetFVF(kQuadFvf) == D3D_OK);
    auto v = quad(W, H, 0xffffffff);
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLELIST, 2, v.data(), sizeof(QuadVertex)) == D3D_OK);
    const auto px = readTarget(dev, rt, W, H);
    const uint32_t level2 = 0xff000000u | (2 * 0x30u) << 16 | 0x20u;
    for (uint32_t p : px) CHECK(p == level2);
}

TEST_CASE("draw: untransformed vertices through a perspective projection interpolate perspective-correctly", "[draw]") {
    Device dev;
    const UINT W = 40, H = 30;
    Handle rt = target(dev, W, H, 0);
    shader(dev, "ps_1_1\ntexcoord t0\nmov r0, t0\n");
    REQUIRE(dev.SetFVF(D3DFVF_XYZ | D3DFVF_TEX1) == D3D_OK);
    REQUIRE(dev.SetRenderState(D3DRS_CULLMODE, D3DCULL_NONE) == D3D_OK);
    // Left-handed perspective, near 1, far 10: clip = (x, y, A·z + B, z).
    D3DMATRIX proj;
    const float A = 10.0f / 9.0f, B = -10.0f / 9.0f;
    proj.m[2][2] = A;
    proj.m[2][3] = 1;
    proj.m[3][2] = B;
    proj.m[3][3] = 0;
    REQUIRE(dev.SetTransform(D3DTS_PROJECTION, &proj) == D3D_OK);
    struct V {
        float x, y, z, u, v;
    };
    // A rectangle leaning away: x = −1 + 2u, y = −1 + 3v, z = 1 + 3v (near edge z = 1, far z = 4).
    const V q[4] = {{-1, -1, 1, 0, 0}, {1, -1, 1, 1, 0}, {-1, 2, 4, 0, 1}, {1, 2, 4, 1, 1}};
    REQUIRE(dev.DrawPrimitiveUP(D3DPT_TRIANGLESTRIP, 2, q, sizeof(V)) == D3D_OK);
    const auto px = readTarget(dev, rt, W, H);
    int bad = 0, checked = 0;
    for (UINT y = 0; y < H; ++y)
        for (UINT x = 0; x < W; ++x) {
            // Pixel centre → ndc: x_ndc = 2x/W − 1, y_ndc = 1 − 2y/H. On the plane
            // y_ndc = (−1 + 3v)/(1 + 3v) → v = (y_ndc + 1)/(3(1 − y_ndc)); then z = 1 + 3v and
            // u = (x_ndc·z + 1)/2.
            const double xn = 2.0 * x / W - 1, yn = 1 - 2.0 * y / H;
            const double v = (yn + 1) / (3 * (1 - yn));
            const double u = (xn * (1 + 3 * v) + 1) / 2;
            const uint32_t got = px[y * W + x];
            if (u > 0.01 && u < 0.99 && v > 0.01 && v < 0.99) {
                ++checked;
                const int eu = int(std::lround(u * 255)), ev = int(std::lround(v * 255));
                const int gu = int(channel(got, 0)), gv = int(channel(got, 1));
                if (std::abs(gu - eu) > 1 || std::abs(gv - ev) > 1) {
                    if (bad < 6) WARN(x << "," << y << " got " << gu << "," << gv << " want " << eu << "," << ev);
                    ++bad;
                }
            } else if (u < -0.01 || u > 1.01 || v < -0.01 || v > 1.01) {
                ++checked;
                if (got != 0) ++bad;  // outside the rectangle: untouched
            }
        }
    CHECK(checked > int(W * H) * 3 / 4);
    CHECK(bad == 0);
}
