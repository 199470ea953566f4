// The fixed-function lowering (emu/ffp.cpp, docs/fixed-function.md): texture stage states are
// lowered, the program runs on ps11::Executor, and every result is compared with the D3D9
// texture-blending formulas evaluated here independently — exact rational arithmetic rounded
// half-even to the grid once per stage (fx8 and fx12, docs/precision.md), and in double against the
// float profile with a tolerance — plus hand-computed values and the E414x errors.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <iterator>
#include <numeric>
#include <random>
#include <vector>

#include "emu/ffp.h"
#include "ps11/disassembler.h"
#include "ps11/executor.h"
#include "ps11/testfile_textures.h"
#include "ps11/texture_sampler.h"

namespace {

using namespace emu;
using ps11::Precision;

using Rgba = std::array<int, 4>;  // 8-bit grid values n, value n/255

struct Pixel {
    Rgba diffuse{}, specular{};
    std::array<Rgba, kMaxFixedFunctionTextures> tex{};
    float u = 0.5f, v = 0.5f;  // texture coordinates of every set (used by the TextureSampler tests)
};

// Returns each lane's chosen texel per stage (lane i = pixel i; spans stay below one chunk).
class PixelSampler final : public ps11::Sampler {
public:
    explicit PixelSampler(const std::vector<Pixel>& px) : m_px(px) {}
    void sample(const ps11::SampleRequest& req, ps11::SampleResult& out) override {
        for (int i = 0; i < req.count; ++i) {
            const Rgba t =
                req.stage < kMaxFixedFunctionTextures ? m_px[size_t(i)].tex[size_t(req.stage)] : Rgba{0, 0, 0, 255};
            for (int c = 0; c < 4; ++c) {
                if (out.grid[c]) out.grid[c][i] = t[size_t(c)] * (req.precision == Precision::Fx12 ? 16 : 1);
                if (out.value[c]) out.value[c][i] = float(t[size_t(c)]) / 255.0f;
            }
        }
        requests |= 1u << req.stage;
    }
    bool hasTexture(int) const override { return true; }
    uint32_t requests = 0;

private:
    const std::vector<Pixel>& m_px;
};

struct Outputs {
    std::vector<Rgba> grid;
    std::vector<std::array<float, 4>> value;
};

LoweredStages lower(const DeviceState& s) {
    CallError error;
    std::optional<LoweredStages> l = lowerFixedFunction(s, error);
    INFO(error.code + " " + error.message);
    REQUIRE(l);
    CHECK(error.hr == D3D_OK);
    CHECK(error.code.empty());
    CHECK(error.message.empty());
    return *l;
}

Outputs run(const DeviceState& s, const std::vector<Pixel>& px, Precision p, ps11::Sampler* sampler = nullptr) {
    REQUIRE(px.size() <= 64);
    const LoweredStages l = lower(s);
    ps11::Diagnostics diags;
    ps11::ExecutorOptions opt;
    opt.precision = p;
    auto ex = ps11::Executor::create(l.program, opt, diags);
    INFO(diags.formatAll() << ps11::disassemble(l.program));
    REQUIRE(ex);
    for (int i = 0; i < kMaxStages; ++i) ex->setStageState(i, l.executorStages[size_t(i)]);
    const int n = int(px.size());
    std::vector<float> col[2][4], tc[2];
    for (int v = 0; v < 2; ++v)
        for (int c = 0; c < 4; ++c)
            for (const Pixel& q : px) col[v][c].push_back(float((v ? q.specular : q.diffuse)[size_t(c)]) / 255.0f);
    for (const Pixel& q : px) tc[0].push_back(q.u), tc[1].push_back(q.v);
    ps11::PixelInputs in;
    in.count = n;
    for (int v = 0; v < 2; ++v)
        for (int c = 0; c < 4; ++c) in.color[v][c] = col[v][c].data();
    for (int set = 0; set < 8; ++set) in.texcoord[set][0] = tc[0].data(), in.texcoord[set][1] = tc[1].data();
    std::vector<float> outF[4];
    std::vector<int32_t> outG[4];
    ps11::PixelOutputs out;
    for (int c = 0; c < 4; ++c) {
        outF[c].resize(size_t(n));
        outG[c].resize(size_t(n));
        out.color[c] = outF[c].data();
        out.grid[c] = outG[c].data();
    }
    PixelSampler own(px);
    ex->run(in, sampler ? *sampler : own, out);
    Outputs r;
    for (int i = 0; i < n; ++i) {
        Rgba g;
        std::array<float, 4> f;
        for (int c = 0; c < 4; ++c) g[size_t(c)] = outG[c][size_t(i)], f[size_t(c)] = outF[c][size_t(i)];
        r.grid.push_back(g);
        r.value.push_back(f);
    }
    return r;
}

// ---- The reference: D3D9's texture-blending formulas over exact rationals or doubles ----------

// An exact rational p/q (q > 0), enough for one stage's products of 8-bit values.
struct Q {
    int64_t p = 0, q = 1;
    Q() = default;
    Q(int64_t p_, int64_t q_ = 1) : p(p_), q(q_) { norm(); }
    void norm() {
        if (q < 0) p = -p, q = -q;
        int64_t g = std::gcd(p < 0 ? -p : p, q);
        if (g > 1) p /= g, q /= g;
    }
    friend Q operator+(Q a, Q b) { return Q(a.p * b.q + b.p * a.q, a.q * b.q); }
    friend Q operator-(Q a, Q b) { return Q(a.p * b.q - b.p * a.q, a.q * b.q); }
    friend Q operator*(Q a, Q b) { return Q(a.p * b.p, a.q * b.q); }
};

// round_half_even(p/q), q > 0.
int64_t roundHalfEven(int64_t p, int64_t q) {
    int64_t fl = p >= 0 ? p / q : -((-p + q - 1) / q);
    int64_t rem2 = 2 * (p - fl * q);  // in [0, 2q)
    if (rem2 > q || (rem2 == q && (fl & 1))) ++fl;
    return fl;
}

// fx: a stage result is rounded once to the grid G (ties to even) and saturated.
Q stageRound(Q v, int64_t g) {
    int64_t n = roundHalfEven(v.p * g, v.q);
    return Q(n < 0 ? 0 : n > g ? g : n, g);
}
// float: saturated only.
double stageRound(double v, int64_t) { return v < 0 ? 0 : v > 1 ? 1 : v; }

template <class T>
T fromGrid(int n) {
    if constexpr (std::is_same_v<T, Q>)
        return Q(n, 255);
    else
        return double(n) / 255.0;
}
template <class T>
T half() {
    if constexpr (std::is_same_v<T, Q>)
        return Q(1, 2);
    else
        return 0.5;
}

template <class T>
using Vec = std::array<T, 4>;

template <class T>
Vec<T> gridVec(const Rgba& c) {
    return {fromGrid<T>(c[0]), fromGrid<T>(c[1]), fromGrid<T>(c[2]), fromGrid<T>(c[3])};
}
template <class T>
Vec<T> colorVec(DWORD argb) {
    return gridVec<T>(Rgba{int((argb >> 16) & 255), int((argb >> 8) & 255), int(argb & 255), int(argb >> 24)});
}

// The D3DTEXTUREOP formula for channel c (docs: D3DTEXTUREOP, "Texture Blending").
template <class T>
T opFormula(DWORD op, int c, const Vec<T>& a0, const Vec<T>& a1, const Vec<T>& a2, T diffuseA, T textureA, T factorA,
            T currentA) {
    const T one = fromGrid<T>(255);
    const T x0 = a0[size_t(c)], x1 = a1[size_t(c)], x2 = a2[size_t(c)];
    switch (op) {
        case D3DTOP_SELECTARG1:
        case D3DTOP_PREMODULATE:  // this stage's part; the next stage modulates
            return x1;
        case D3DTOP_SELECTARG2:
            return x2;
        case D3DTOP_MODULATE:
            return x1 * x2;
        case D3DTOP_MODULATE2X:
            return (x1 * x2) * T(2);
        case D3DTOP_MODULATE4X:
            return (x1 * x2) * T(4);
        case D3DTOP_ADD:
            return x1 + x2;
        case D3DTOP_ADDSIGNED:
            return x1 + x2 - half<T>();
        case D3DTOP_ADDSIGNED2X:
            return (x1 + x2 - half<T>()) * T(2);
        case D3DTOP_SUBTRACT:
            return x1 - x2;
        case D3DTOP_ADDSMOOTH:
            return x1 + x2 - x1 * x2;
        case D3DTOP_BLENDDIFFUSEALPHA:
            return x1 * diffuseA + x2 * (one - diffuseA);
        case D3DTOP_BLENDTEXTUREALPHA:
            return x1 * textureA + x2 * (one - textureA);
        case D3DTOP_BLENDFACTORALPHA:
            return x1 * factorA + x2 * (one - factorA);
        case D3DTOP_BLENDTEXTUREALPHAPM:
            return x1 + x2 * (one - textureA);
        case D3DTOP_BLENDCURRENTALPHA:
            return x1 * currentA + x2 * (one - currentA);
        case D3DTOP_MODULATEALPHA_ADDCOLOR:
            return x1 + a1[3] * x2;
        case D3DTOP_MODULATECOLOR_ADDALPHA:
            return x1 * x2 + a1[3];
        case D3DTOP_MODULATEINVALPHA_ADDCOLOR:
            return (one - a1[3]) * x2 + x1;
        case D3DTOP_MODULATEINVCOLOR_ADDALPHA:
            return (one - x1) * x2 + a1[3];
        case D3DTOP_DOTPRODUCT3: {
            T s = T(0);
            for (int k = 0; k < 3; ++k) s = s + (a1[size_t(k)] * T(2) - one) * (a2[size_t(k)] * T(2) - one);
            return s;
        }
        case D3DTOP_MULTIPLYADD:
            return x1 * x2 + x0;
        case D3DTOP_LERP:
            return x0 * x1 + (one - x0) * x2;
        default:
            FAIL("reference has no formula for op " << op);
            return T(0);
    }
}

// The whole texture cascade of `s` for one pixel (no bump stages), D3D9 semantics: CURRENT
// starts as diffuse, TEMP as 0, COLOROP DISABLE ends the cascade, ALPHAOP DISABLE keeps the
// destination's alpha, DOTPRODUCT3 writes all four channels, PREMODULATE selects ARG1 and the next
// stage first multiplies those channels by its texture, the specular rgb is added last.
template <class T>
Vec<T> reference(const DeviceState& s, const Pixel& px, int64_t g = 255) {
    const Vec<T> diffuse = gridVec<T>(px.diffuse), specular = gridVec<T>(px.specular);
    const Vec<T> tfactor = colorVec<T>(s.renderState(D3DRS_TEXTUREFACTOR));
    Vec<T> cur = diffuse, temp{T(0), T(0), T(0), T(0)};
    const T one = fromGrid<T>(255);
    bool premod[4] = {false, false, false, false};  // channels the previous stage PREMODULATEd
    bool premodTemp = false;
    for (int i = 0; i < kMaxStages; ++i) {
        const DWORD cop = s.stageState(i, D3DTSS_COLOROP);
        if (cop == D3DTOP_DISABLE) break;
        const Vec<T> tex = i < kMaxFixedFunctionTextures ? gridVec<T>(px.tex[size_t(i)]) : Vec<T>{};
        for (int c = 0; c < 4; ++c) {
            Vec<T>& r = premodTemp ? temp : cur;
            if (premod[c]) r[size_t(c)] = stageRound(r[size_t(c)] * tex[size_t(c)], g);
            premod[c] = false;
        }
        auto argv = [&](DWORD a) {
            Vec<T> v;
            switch (a & D3DTA_SELECTMASK) {
                case D3DTA_DIFFUSE:
                    v = diffuse;
                    break;
                case D3DTA_CURRENT:
                    v = cur;
                    break;
                case D3DTA_TEXTURE:
                    v = tex;
                    break;
                case D3DTA_TFACTOR:
                    v = tfactor;
                    break;
                case D3DTA_SPECULAR:
                    v = specular;
                    break;
                case D3DTA_TEMP:
                    v = temp;
                    break;
                default:
                    v = colorVec<T>(s.stageState(i, D3DTSS_CONSTANT));
                    break;
            }
            if (a & D3DTA_COMPLEMENT)
                for (T& x : v) x = one - x;
            if (a & D3DTA_ALPHAREPLICATE) v = {v[3], v[3], v[3], v[3]};
            return v;
        };
        const bool toTemp = s.stageState(i, D3DTSS_RESULTARG) == D3DTA_TEMP;
        Vec<T> res = toTemp ? temp : cur;
        const Vec<T> c0 = argv(s.stageState(i, D3DTSS_COLORARG0)), c1 = argv(s.stageState(i, D3DTSS_COLORARG1)),
                     c2 = argv(s.stageState(i, D3DTSS_COLORARG2));
        const Vec<T> al0 = argv(s.stageState(i, D3DTSS_ALPHAARG0)), al1 = argv(s.stageState(i, D3DTSS_ALPHAARG1)),
                     al2 = argv(s.stageState(i, D3DTSS_ALPHAARG2));
        if (cop == D3DTOP_DOTPRODUCT3) {
            T d = stageRound(opFormula<T>(cop, 0, c0, c1, c2, diffuse[3], tex[3], tfactor[3], cur[3]), g);
            res = {d, d, d, d};
        } else {
            for (int c = 0; c < 3; ++c)
                res[size_t(c)] =
                    stageRound(opFormula<T>(cop, c, c0, c1, c2, diffuse[3], tex[3], tfactor[3], cur[3]), g);
            const DWORD aop = s.stageState(i, D3DTSS_ALPHAOP);
            if (aop != D3DTOP_DISABLE)
                res[3] = stageRound(opFormula<T>(aop, 3, al0, al1, al2, diffuse[3], tex[3], tfactor[3], cur[3]), g);
        }
        (toTemp ? temp : cur) = res;
        premodTemp = toTemp;
        for (int c = 0; c < 3; ++c) premod[c] = cop == D3DTOP_PREMODULATE;
        premod[3] = cop != D3DTOP_DOTPRODUCT3 && s.stageState(i, D3DTSS_ALPHAOP) == D3DTOP_PREMODULATE;
    }
    if (s.renderState(D3DRS_SPECULARENABLE))
        for (int c = 0; c < 3; ++c) cur[size_t(c)] = stageRound(cur[size_t(c)] + specular[size_t(c)], g);
    return cur;
}

// The reference's grid integers in an fx profile of grid scale g (255: fx8, 4080: fx12).
Rgba referenceGrid(const DeviceState& s, const Pixel& px, int64_t g) {
    Vec<Q> v = reference<Q>(s, px, g);
    Rgba r;
    for (int c = 0; c < 4; ++c) r[size_t(c)] = int(roundHalfEven(v[size_t(c)].p * g, v[size_t(c)].q));
    return r;
}

std::vector<Pixel> randomPixels(std::mt19937& rng, int n) {
    std::uniform_int_distribution<int> d(0, 255);
    std::vector<Pixel> px(static_cast<size_t>(n));
    for (Pixel& p : px) {
        for (int c = 0; c < 4; ++c) {
            p.diffuse[size_t(c)] = d(rng);
            p.specular[size_t(c)] = d(rng);
            for (Rgba& t : p.tex) t[size_t(c)] = d(rng);
        }
    }
    // Edge values: all zero, all one, mid grey.
    for (int c = 0; c < 4; ++c) {
        px[0].diffuse[size_t(c)] = 0, px[0].specular[size_t(c)] = 0, px[0].tex[0][size_t(c)] = 0;
        px[1].diffuse[size_t(c)] = 255, px[1].specular[size_t(c)] = 255, px[1].tex[0][size_t(c)] = 255;
        px[2].diffuse[size_t(c)] = 128, px[2].specular[size_t(c)] = 127, px[2].tex[0][size_t(c)] = 128;
    }
    return px;
}

std::string rgbaText(const Rgba& c) {
    return "(" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," + std::to_string(c[2]) + "," +
           std::to_string(c[3]) + ")";
}

// Runs `s` in fx8, fx12 and float and compares every pixel with the reference; returns mismatches.
int compareWithReference(const DeviceState& s, const std::vector<Pixel>& px) {
    const Outputs fx = run(s, px, Precision::Fx8);
    const Outputs fx12 = run(s, px, Precision::Fx12);
    const Outputs fl = run(s, px, Precision::Float);
    int bad = 0;
    for (size_t i = 0; i < px.size(); ++i) {
        const Rgba want = referenceGrid(s, px[i], 255);
        const Rgba want12 = referenceGrid(s, px[i], 4080);
        const Vec<double> wantF = reference<double>(s, px[i]);
        bool ok = fx.grid[i] == want;
        if (fx12.grid[i] != want12) {
            ok = false;
            UNSCOPED_INFO("pixel " << i << " fx12 " << rgbaText(fx12.grid[i]) << " want " << rgbaText(want12));
        }
        for (int c = 0; c < 4; ++c) ok = ok && std::fabs(fl.value[i][size_t(c)] - wantF[size_t(c)]) < 2e-5;
        if (!ok) {
            ++bad;
            UNSCOPED_INFO("pixel " << i << " fx8 " << rgbaText(fx.grid[i]) << " want " << rgbaText(want) << " float "
                                   << fl.value[i][0] << "," << fl.value[i][1] << "," << fl.value[i][2] << ","
                                   << fl.value[i][3] << " want " << wantF[0] << "," << wantF[1] << "," << wantF[2]
                                   << "," << wantF[3]);
        }
    }
    return bad;
}

void setStage(DeviceState& s, int i, DWORD cop, DWORD c1, DWORD c2, DWORD aop, DWORD a1, DWORD a2) {
    s.stageStates[size_t(i)][D3DTSS_COLOROP] = cop;
    s.stageStates[size_t(i)][D3DTSS_COLORARG1] = c1;
    s.stageStates[size_t(i)][D3DTSS_COLORARG2] = c2;
    s.stageStates[size_t(i)][D3DTSS_ALPHAOP] = aop;
    s.stageStates[size_t(i)][D3DTSS_ALPHAARG1] = a1;
    s.stageStates[size_t(i)][D3DTSS_ALPHAARG2] = a2;
}

const DWORD kBlendOps[] = {
    D3DTOP_SELECTARG1,
    D3DTOP_PREMODULATE,
    D3DTOP_SELECTARG2,
    D3DTOP_MODULATE,
    D3DTOP_MODULATE2X,
    D3DTOP_MODULATE4X,
    D3DTOP_ADD,
    D3DTOP_ADDSIGNED,
    D3DTOP_ADDSIGNED2X,
    D3DTOP_SUBTRACT,
    D3DTOP_ADDSMOOTH,
    D3DTOP_BLENDDIFFUSEALPHA,
    D3DTOP_BLENDTEXTUREALPHA,
    D3DTOP_BLENDFACTORALPHA,
    D3DTOP_BLENDTEXTUREALPHAPM,
    D3DTOP_BLENDCURRENTALPHA,
    D3DTOP_MODULATEALPHA_ADDCOLOR,
    D3DTOP_MODULATECOLOR_ADDALPHA,
    D3DTOP_MODULATEINVALPHA_ADDCOLOR,
    D3DTOP_MODULATEINVCOLOR_ADDALPHA,
    D3DTOP_DOTPRODUCT3,
    D3DTOP_MULTIPLYADD,
    D3DTOP_LERP,
};
bool alphaCapable(DWORD op) { return op < D3DTOP_MODULATEALPHA_ADDCOLOR || op > D3DTOP_MODULATEINVCOLOR_ADDALPHA; }

}  // namespace

TEST_CASE("ffp: every colour operation equals its D3D formula (fx8, fx12 exact, float)", "[ffp]") {
    std::mt19937 rng(11);
    const std::vector<Pixel> px = randomPixels(rng, 48);
    for (DWORD op : kBlendOps) {
        // Stage 1 so that CURRENT is stage 0's result (texture 0 · diffuse), not diffuse itself.
        DeviceState s;
        setStage(s, 0, D3DTOP_MODULATE, D3DTA_TEXTURE, D3DTA_DIFFUSE, D3DTOP_SELECTARG2, D3DTA_TEXTURE, D3DTA_DIFFUSE);
        setStage(s, 1, op, D3DTA_TEXTURE, D3DTA_CURRENT, D3DTOP_SELECTARG1, D3DTA_SPECULAR, D3DTA_CURRENT);
        s.stageStates[1][D3DTSS_COLORARG0] = D3DTA_SPECULAR;
        s.renderStates[D3DRS_TEXTUREFACTOR] = 0x80C04020;
        INFO("COLOROP " << op);
        CHECK(compareWithReference(s, px) == 0);
    }
}

TEST_CASE("ffp: every alpha operation equals its D3D formula (fx8, fx12 exact, float)", "[ffp]") {
    std::mt19937 rng(12);
    const std::vector<Pixel> px = randomPixels(rng, 48);
    for (DWORD op : kBlendOps) {
        if (!alphaCapable(op)) continue;
        DeviceState s;
        setStage(s, 0, D3DTOP_MODULATE, D3DTA_TEXTURE, D3DTA_DIFFUSE, D3DTOP_MODULATE, D3DTA_TEXTURE, D3DTA_DIFFUSE);
        setStage(s, 1, D3DTOP_SELECTARG2, D3DTA_TEXTURE, D3DTA_CURRENT, op, D3DTA_TEXTURE, D3DTA_CURRENT);
        s.stageStates[1][D3DTSS_ALPHAARG0] = D3DTA_SPECULAR;
        s.renderStates[D3DRS_TEXTUREFACTOR] = 0x3DC04020;
        INFO("ALPHAOP " << op);
        CHECK(compareWithReference(s, px) == 0);
    }
}

TEST_CASE("ffp: every argument source with COMPLEMENT and ALPHAREPLICATE", "[ffp]") {
    std::mt19937 rng(13);
    const std::vector<Pixel> px = randomPixels(rng, 32);
    const DWORD sources[] = {D3DTA_DIFFUSE,  D3DTA_CURRENT, D3DTA_TEXTURE, D3DTA_TFACTOR,
                             D3DTA_SPECULAR, D3DTA_TEMP,    D3DTA_CONSTANT};
    const DWORD mods[] = {0, D3DTA_COMPLEMENT, D3DTA_ALPHAREPLICATE, D3DTA_COMPLEMENT | D3DTA_ALPHAREPLICATE};
    // Ops whose lowering rewrites the argument's modifier (bias, _bx2, inversion) are included.
    const DWORD ops[] = {D3DTOP_MODULATE,
                         D3DTOP_ADDSIGNED,
                         D3DTOP_ADDSMOOTH,
                         D3DTOP_DOTPRODUCT3,
                         D3DTOP_MODULATEINVALPHA_ADDCOLOR,
                         D3DTOP_MODULATEINVCOLOR_ADDALPHA,
                         D3DTOP_SUBTRACT};
    int configs = 0;
    for (DWORD src : sources)
        for (DWORD mod : mods)
            for (DWORD op : ops) {
                for (int which = 0; which < 2; ++which) {  // the argument as ARG1, then as ARG2
                    DeviceState s;
                    s.renderStates[D3DRS_TEXTUREFACTOR] = 0xC0306090;
                    // Stage 0 fills TEMP; stage 1 is the tested one (its CURRENT is diffuse still).
                    setStage(s, 0, D3DTOP_MODULATE2X, D3DTA_TEXTURE, D3DTA_SPECULAR, D3DTOP_ADD, D3DTA_TEXTURE,
                             D3DTA_SPECULAR);
                    s.stageStates[0][D3DTSS_RESULTARG] = D3DTA_TEMP;
                    const DWORD a = src | mod, other = D3DTA_TEXTURE | (which ? D3DTA_COMPLEMENT : 0);
                    setStage(s, 1, op, which ? other : a, which ? a : other, alphaCapable(op) ? op : D3DTOP_SUBTRACT,
                             which ? other : a, which ? a : other);
                    s.stageStates[1][D3DTSS_CONSTANT] = 0x5AA5F00F;
                    INFO("source " << src << " modifiers " << mod << " op " << op << " as ARG" << (which + 1));
                    CHECK(compareWithReference(s, px) == 0);
                    ++configs;
                }
            }
    CHECK(configs == 7 * 4 * 7 * 2);
}

TEST_CASE("ffp: ARG0 of MULTIPLYADD and LERP with modifiers", "[ffp]") {
    std::mt19937 rng(14);
    const std::vector<Pixel> px = randomPixels(rng, 32);
    for (DWORD op : {D3DTOP_MULTIPLYADD, D3DTOP_LERP})
        for (DWORD a0 : {D3DTA_SPECULAR, D3DTA_TFACTOR | D3DTA_COMPLEMENT, D3DTA_TEXTURE | D3DTA_ALPHAREPLICATE,
                         D3DTA_DIFFUSE | D3DTA_COMPLEMENT | D3DTA_ALPHAREPLICATE}) {
            DeviceState s;
            s.renderStates[D3DRS_TEXTUREFACTOR] = 0x11223344;
            setStage(s, 0, op, D3DTA_TEXTURE, D3DTA_DIFFUSE, op, D3DTA_DIFFUSE, D3DTA_TEXTURE);
            s.stageStates[0][D3DTSS_COLORARG0] = a0;
            s.stageStates[0][D3DTSS_ALPHAARG0] = a0;
            INFO("op " << op << " ARG0 " << a0);
            CHECK(compareWithReference(s, px) == 0);
        }
}

TEST_CASE("ffp: random multi-stage cascades with TEMP, CONSTANT and SPECULARENABLE", "[ffp]") {
    std::mt19937 rng(15);
    const std::vector<Pixel> px = randomPixels(rng, 24);
    std::uniform_int_distribution<int> opPick(0, int(std::size(kBlendOps)) - 1), srcPick(0, 6), modPick(0, 3),
        coin(0, 1), stagesPick(1, kMaxFixedFunctionTextures);
    std::uniform_int_distribution<uint32_t> word(0, 0xffffffffu);
    auto randomArg = [&] { return DWORD(srcPick(rng)) | (DWORD(modPick(rng)) << 4); };
    for (int trial = 0; trial < 120; ++trial) {
        DeviceState s;
        s.renderStates[D3DRS_TEXTUREFACTOR] = word(rng);
        s.renderStates[D3DRS_SPECULARENABLE] = DWORD(coin(rng));
        const int stages = stagesPick(rng);
        for (int i = 0; i < stages; ++i) {
            DWORD cop = kBlendOps[opPick(rng)], aop = kBlendOps[opPick(rng)];
            if (!alphaCapable(aop)) aop = coin(rng) ? D3DTOP_DISABLE : D3DTOP_ADD;
            setStage(s, i, cop, randomArg(), randomArg(), aop, randomArg(), randomArg());
            s.stageStates[size_t(i)][D3DTSS_COLORARG0] = randomArg();
            s.stageStates[size_t(i)][D3DTSS_ALPHAARG0] = randomArg();
            s.stageStates[size_t(i)][D3DTSS_RESULTARG] = coin(rng) ? D3DTA_TEMP : D3DTA_CURRENT;
            s.stageStates[size_t(i)][D3DTSS_CONSTANT] = word(rng);
        }
        INFO("trial " << trial << "\n" << ps11::disassemble(lower(s).program));
        CHECK(compareWithReference(s, px) == 0);
    }
}

TEST_CASE("ffp: hand-computed results", "[ffp]") {
    std::vector<Pixel> px(1);
    px[0].diffuse = {200, 100, 0, 51};
    px[0].specular = {100, 200, 30, 77};
    px[0].tex[0] = {128, 64, 255, 102};
    px[0].tex[1] = {0, 129, 255, 128};
    auto one = [&](const DeviceState& s) { return run(s, px, Precision::Fx8).grid[0]; };

    DeviceState s;  // D3D9 defaults: MODULATE texture·diffuse, alpha SELECTARG1 texture
    // 128·200/255 = 100.39 -> 100; 64·100/255 = 25.1 -> 25; 0; alpha 102.
    CHECK(one(s) == Rgba{100, 25, 0, 102});

    // ADDSIGNED (stage 1, CURRENT = diffuse from stage 0), colour tex1 + (1 − diffuse) − 0.5:
    // 0 + 55 − 127.5 < 0 -> 0; 129 + 155 − 127.5 = 156.5 -> 156 (tie to even); 255 + 255 − 127.5 -> 255.
    // Alpha tex1.a + diffuse.a − 0.5 = 128 + 51 − 127.5 = 51.5 -> 52 (tie to even).
    setStage(s, 0, D3DTOP_SELECTARG1, D3DTA_DIFFUSE, D3DTA_DIFFUSE, D3DTOP_SELECTARG1, D3DTA_DIFFUSE, D3DTA_DIFFUSE);
    setStage(s, 1, D3DTOP_ADDSIGNED, D3DTA_TEXTURE, D3DTA_DIFFUSE | D3DTA_COMPLEMENT, D3DTOP_ADDSIGNED, D3DTA_TEXTURE,
             D3DTA_DIFFUSE);
    CHECK(one(s) == Rgba{0, 156, 255, 52});

    // MODULATE4X saturates (stage 0 selects tex0): 4·128·200/255 = 401.6 -> 255; 4·64·100/255 = 100.39 -> 100;
    // 4·255·0 = 0. ALPHAOP DISABLE keeps CURRENT's alpha, tex0.a = 102.
    setStage(s, 0, D3DTOP_SELECTARG1, D3DTA_TEXTURE, D3DTA_DIFFUSE, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0);
    setStage(s, 1, D3DTOP_MODULATE4X, D3DTA_CURRENT, D3DTA_DIFFUSE, D3DTOP_DISABLE, 0, 0);
    CHECK(one(s) == Rgba{255, 100, 0, 102});
    // MODULATE2X: 2·128·200/255 = 200.78 -> 201; 2·64·100/255 = 50.2 -> 50; alpha kept.
    s.stageStates[1][D3DTSS_COLOROP] = D3DTOP_MODULATE2X;
    CHECK(one(s) == Rgba{201, 50, 0, 102});

    // DOTPRODUCT3 replicated to alpha: (2·128−255)(2·200−255) + (128−255)(200−255) + (255)(−255) over 255
    // = (1·145 + (−127)(−55) + 255·(−255))/255 < 0 -> 0 for tex0·diffuse; with tex0·tex0:
    // (1 + 127² + 255²)/255 = (1 + 16129 + 65025)/255 = 318.3 -> 255.
    s = DeviceState();
    setStage(s, 0, D3DTOP_DOTPRODUCT3, D3DTA_TEXTURE, D3DTA_DIFFUSE, D3DTOP_SELECTARG1, D3DTA_DIFFUSE, 0);
    CHECK(one(s) == Rgba{0, 0, 0, 0});
    s.stageStates[0][D3DTSS_COLORARG2] = D3DTA_TEXTURE;
    CHECK(one(s) == Rgba{255, 255, 255, 255});
    // tfactor (128, 128, 255) · tex0 (0, 129, 255): signed (1/255)(−1) + (1/255)(3/255) + 1·1 in grid
    // steps: 255 − 1 + 3/255 = 254.01 -> 254, in all four channels.
    s.stageStates[0][D3DTSS_COLORARG1] = D3DTA_TFACTOR;
    s.renderStates[D3DRS_TEXTUREFACTOR] = 0xFF8080FF;
    px[0].tex[0] = {0, 129, 255, 0};
    CHECK(one(s) == Rgba{254, 254, 254, 254});

    // SPECULARENABLE adds specular rgb to CURRENT with saturation, alpha untouched:
    // diffuse (200,100,0,51) + specular (100,200,30) = (255, 255, 30, 51).
    s = DeviceState();
    s.stageStates[0][D3DTSS_COLOROP] = D3DTOP_DISABLE;
    s.renderStates[D3DRS_SPECULARENABLE] = 1;
    CHECK(one(s) == Rgba{255, 255, 30, 51});

    // TFACTOR and CONSTANT: LERP(constant.a, tfactor, diffuse): constant a = 0x40 = 64,
    // tfactor (0x10, 0x20, 0xF0): (64·16 + 191·200)/255 = 153.8 -> 154; (64·32 + 191·100)/255 = 82.9 -> 83;
    // (64·240 + 0)/255 = 60.2 -> 60. Alpha SELECTARG1 CONSTANT -> 64.
    s = DeviceState();
    s.renderStates[D3DRS_TEXTUREFACTOR] = 0x771020F0;
    setStage(s, 0, D3DTOP_LERP, D3DTA_TFACTOR, D3DTA_DIFFUSE, D3DTOP_SELECTARG1, D3DTA_CONSTANT, 0);
    s.stageStates[0][D3DTSS_COLORARG0] = D3DTA_CONSTANT | D3DTA_ALPHAREPLICATE;
    s.stageStates[0][D3DTSS_CONSTANT] = 0x40000000;
    CHECK(one(s) == Rgba{154, 83, 60, 64});
}

TEST_CASE("ffp: disable rules", "[ffp]") {
    std::vector<Pixel> px(1);
    px[0].diffuse = {10, 20, 30, 40};
    px[0].specular = {1, 2, 3, 4};
    px[0].tex[0] = {100, 110, 120, 130};
    px[0].tex[1] = {200, 210, 220, 230};
    px[0].tex[2] = {50, 60, 70, 80};
    auto one = [&](const DeviceState& s) { return run(s, px, Precision::Fx8).grid[0]; };

    // COLOROP DISABLE on stage 0 disables texturing: the pixel is the diffuse colour, and the
    // default ALPHAOP (SELECTARG1 texture) of the disabled stage is ignored.
    DeviceState s;
    s.stageStates[0][D3DTSS_COLOROP] = D3DTOP_DISABLE;
    LoweredStages l = lower(s);
    CHECK(l.activeStages == 0);
    CHECK(l.sampledStages == 0);
    CHECK(one(s) == Rgba{10, 20, 30, 40});

    // A disabled stage 1 hides stage 2 entirely (its texture is not even sampled).
    s = DeviceState();
    setStage(s, 0, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0);
    setStage(s, 2, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0);
    l = lower(s);
    CHECK(l.activeStages == 1);
    CHECK(l.sampledStages == 1u);
    CHECK(one(s) == Rgba{100, 110, 120, 130});
    s.stageStates[1][D3DTSS_COLOROP] = D3DTOP_SELECTARG1;  // now stage 2 runs: its ALPHAOP too
    s.stageStates[1][D3DTSS_COLORARG1] = D3DTA_CURRENT;
    CHECK(lower(s).sampledStages == 5u);
    CHECK(one(s) == Rgba{50, 60, 70, 80});

    // ALPHAOP DISABLE with the colour enabled keeps the destination's alpha: stage 0's CURRENT
    // alpha is diffuse's; a TEMP destination that was never written keeps TEMP's 0.
    s = DeviceState();
    setStage(s, 0, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0, D3DTOP_DISABLE, D3DTA_TEXTURE, 0);
    CHECK(one(s) == Rgba{100, 110, 120, 40});
    s.stageStates[0][D3DTSS_RESULTARG] = D3DTA_TEMP;
    setStage(s, 1, D3DTOP_ADD, D3DTA_TEMP, D3DTA_CURRENT, D3DTOP_ADD, D3DTA_TEMP, D3DTA_CURRENT);
    // CURRENT is still diffuse: (100+10, 110+20, 120+30, 0+40).
    CHECK(one(s) == Rgba{110, 130, 150, 40});

    // DOTPRODUCT3 as COLOROP writes alpha too; the stage's ALPHAOP is not used.
    s = DeviceState();
    setStage(s, 0, D3DTOP_DOTPRODUCT3, D3DTA_TEXTURE, D3DTA_TEXTURE, D3DTOP_SELECTARG1, D3DTA_DIFFUSE, 0);
    const Rgba dot = one(s);
    CHECK(dot[3] == dot[0]);
    CHECK(dot[3] != 40);
}

TEST_CASE("ffp: PREMODULATE selects ARG1 and the next stage multiplies it by its texture", "[ffp]") {
    std::vector<Pixel> px(1);
    px[0].diffuse = {200, 100, 50, 255};
    px[0].tex[0] = {9, 9, 9, 9};
    px[0].tex[1] = {128, 255, 0, 64};
    DeviceState s;
    setStage(s, 0, D3DTOP_PREMODULATE, D3DTA_DIFFUSE, 0, D3DTOP_PREMODULATE, D3DTA_DIFFUSE, 0);
    setStage(s, 1, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
    // 200·128/255 = 100.39 -> 100; 100·255/255 = 100; 50·0 = 0; 255·64/255 = 64.
    CHECK(run(s, px, Precision::Fx8).grid[0] == Rgba{100, 100, 0, 64});
    CHECK(lower(s).sampledStages == 2u);
    // Only the colour half premodulated: alpha stays diffuse's.
    s.stageStates[0][D3DTSS_ALPHAOP] = D3DTOP_SELECTARG1;
    CHECK(run(s, px, Precision::Fx8).grid[0] == Rgba{100, 100, 0, 255});
    // In the last stage there is no next texture: the result is ARG1.
    s.stageStates[1][D3DTSS_COLOROP] = D3DTOP_DISABLE;
    CHECK(run(s, px, Precision::Fx8).grid[0] == Rgba{200, 100, 50, 255});
    CHECK(lower(s).sampledStages == 0u);

    // Through TEMP, against the reference in every profile.
    std::mt19937 rng(16);
    const std::vector<Pixel> many = randomPixels(rng, 32);
    s = DeviceState();
    setStage(s, 0, D3DTOP_PREMODULATE, D3DTA_TEXTURE, 0, D3DTOP_PREMODULATE, D3DTA_SPECULAR, 0);
    s.stageStates[0][D3DTSS_RESULTARG] = D3DTA_TEMP;
    setStage(s, 1, D3DTOP_ADD, D3DTA_TEMP, D3DTA_CURRENT, D3DTOP_MODULATE, D3DTA_TEMP, D3DTA_TEXTURE);
    setStage(s, 2, D3DTOP_PREMODULATE, D3DTA_CURRENT | D3DTA_COMPLEMENT, 0, D3DTOP_ADD, D3DTA_TEMP, D3DTA_CURRENT);
    setStage(s, 3, D3DTOP_MODULATE2X, D3DTA_CURRENT, D3DTA_DIFFUSE, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
    CHECK(compareWithReference(s, many) == 0);
}

TEST_CASE("ffp: RESULTARG TEMP, TFACTOR and CONSTANT by hand", "[ffp]") {
    std::vector<Pixel> px(1);
    px[0].diffuse = {255, 128, 0, 200};
    px[0].specular = {30, 60, 90, 120};
    px[0].tex[0] = {51, 102, 153, 204};
    px[0].tex[1] = {255, 255, 0, 0};
    DeviceState s;
    // stage 0: TEMP = texture0 · specular; stage 1: CURRENT = diffuse · TFACTOR;
    // stage 2: CURRENT = CURRENT + TEMP.
    setStage(s, 0, D3DTOP_MODULATE, D3DTA_TEXTURE, D3DTA_SPECULAR, D3DTOP_MODULATE, D3DTA_TEXTURE, D3DTA_SPECULAR);
    s.stageStates[0][D3DTSS_RESULTARG] = D3DTA_TEMP;
    setStage(s, 1, D3DTOP_MODULATE, D3DTA_DIFFUSE, D3DTA_TFACTOR, D3DTOP_MODULATE, D3DTA_DIFFUSE, D3DTA_TFACTOR);
    setStage(s, 2, D3DTOP_ADD, D3DTA_CURRENT, D3DTA_TEMP, D3DTOP_ADD, D3DTA_CURRENT, D3DTA_TEMP);
    s.renderStates[D3DRS_TEXTUREFACTOR] = 0x80FF4000;  // a 128, r 255, g 64, b 0
    // TEMP: 51·30/255 = 6; 102·60/255 = 24; 153·90/255 = 54; 204·120/255 = 96.
    // CURRENT: 255·255/255 = 255; 128·64/255 = 32.13 -> 32; 0; 200·128/255 = 100.39 -> 100.
    // sum: (255, 56, 54, 196).
    CHECK(run(s, px, Precision::Fx8).grid[0] == Rgba{255, 56, 54, 196});
    // The final colour is CURRENT even when the last stage writes TEMP.
    s.stageStates[2][D3DTSS_RESULTARG] = D3DTA_TEMP;
    CHECK(run(s, px, Precision::Fx8).grid[0] == Rgba{255, 32, 0, 100});
    // fx12 keeps the 8-bit inputs exact and rounds on its finer grid: 128·64/255 = 32.125 -> 32.125·16 = 514 of 4080.
    const Outputs fx12 = run(s, px, Precision::Fx12);
    CHECK(fx12.grid[0][1] == 514);
}

namespace {

ps11::TextureDesc describe(ps11::TexFormat f, uint32_t w, std::initializer_list<uint32_t> words) {
    ps11::TextureDesc d;
    d.format = {f, 1};
    d.width = w, d.height = 1, d.depth = 0;
    d.sizeLine = 1;
    d.levels = {1, 1};
    ps11::TextureLevel l;
    l.width = w, l.height = 1, l.depth = 1;
    for (uint32_t x : words) {
        ps11::Texel t;
        t.bits = x;
        l.texels.push_back(t);
    }
    d.data.push_back(l);
    return d;
}

std::shared_ptr<const ps11::Texture> build(const ps11::TextureDesc& d) {
    std::string error;
    std::optional<ps11::Texture> t = ps11::textureFromDesc(d, ps11::SignedDecode::Snorm, error);
    INFO(error);
    REQUIRE(t);
    return std::make_shared<const ps11::Texture>(std::move(*t));
}

}  // namespace

TEST_CASE("ffp: BUMPENVMAP perturbs the next stage's lookup with the bump stage's matrix", "[ffp]") {
    // Bump map (V8U8, 4 texels): du = 0, 64, 127, -128 (dv 0); environment map 4 distinct texels.
    ps11::TextureSampler sampler;
    sampler.bind(0, build(describe(ps11::TexFormat::V8U8, 4, {0x0000, 0x0040, 0x007F, 0x0080})));
    const uint32_t env[4] = {0xFF102030, 0x80405060, 0x40708090, 0x20A0B0C0};
    sampler.bind(1, build(describe(ps11::TexFormat::A8R8G8B8, 4, {env[0], env[1], env[2], env[3]})));
    DeviceState s;
    setStage(s, 0, D3DTOP_BUMPENVMAP, D3DTA_TEXTURE, D3DTA_CURRENT, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0);
    s.stageStates[0][D3DTSS_BUMPENVMAT00] = floatBits(0.5f);
    s.stageStates[0][D3DTSS_BUMPENVMAT11] = floatBits(0.5f);
    // Stage 1's own matrix stays 0: D3D9 uses the BUMPENVMAP stage's matrix.
    setStage(s, 1, D3DTOP_MODULATE, D3DTA_TEXTURE, D3DTA_CURRENT, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0);
    const LoweredStages l = lower(s);
    CHECK(l.sampledStages == 3u);
    CHECK(l.executorStages[1].bumpMat[0] == 0.5f);
    CHECK(l.executorStages[1].bumpMat[3] == 0.5f);

    // Pixel k sits on bump texel k (u = 0.125 + 0.25k). u' = u + 0.5·du with du = n/255 of the
    // grid value round(b·255/127): 0 -> 0.125 (env 0); 129/255 -> 0.628 (env 2);
    // 255/255 -> 1.125, wrapped 0.125 (env 0); −1 -> 0.375 (env 1).
    std::vector<Pixel> px(4);
    for (int k = 0; k < 4; ++k) {
        px[size_t(k)].u = 0.125f + 0.25f * float(k);
        px[size_t(k)].v = 0.5f;
        px[size_t(k)].diffuse = {255, 128, 255, 9};  // CURRENT after the bump stage: still diffuse
    }
    const int expectEnv[4] = {0, 2, 0, 1};
    for (Precision p : {Precision::Fx8, Precision::Float}) {
        const Outputs o = run(s, px, p, &sampler);
        for (int k = 0; k < 4; ++k) {
            const uint32_t e = env[expectEnv[k]];
            const int r = int((e >> 16) & 255), g = int((e >> 8) & 255), b = int(e & 255), a = int(e >> 24);
            // MODULATE with diffuse: (r·255, g·128, b·255)/255 rounded half-even.
            const Rgba want{r, int(roundHalfEven(int64_t(g) * 128, 255)), b, a};
            INFO("pixel " << k << " precision " << int(p));
            if (p == Precision::Fx8) {
                CHECK(o.grid[size_t(k)] == want);
            } else {
                for (int c = 0; c < 4; ++c)
                    CHECK(std::fabs(o.value[size_t(k)][size_t(c)] * 255.0f - float(want[size_t(c)])) < 0.51f);
            }
        }
    }
}

TEST_CASE("ffp: BUMPENVMAPLUMINANCE scales the environment texel by the bump stage's luminance", "[ffp]") {
    // X8L8V8U8 bump texels with du = dv = 0 and L = 255, 128, 0, 255; the environment is one colour.
    ps11::TextureSampler sampler;
    sampler.bind(0, build(describe(ps11::TexFormat::X8L8V8U8, 4, {0x00FF0000, 0x00800000, 0x00000000, 0x00FF0000})));
    sampler.bind(1, build(describe(ps11::TexFormat::A8R8G8B8, 4, {0xFFC86428, 0xFFC86428, 0xFFC86428, 0xFFC86428})));
    DeviceState s;
    setStage(s, 0, D3DTOP_BUMPENVMAPLUMINANCE, D3DTA_TEXTURE, D3DTA_CURRENT, D3DTOP_DISABLE, 0, 0);
    s.stageStates[0][D3DTSS_BUMPENVLSCALE] = floatBits(0.5f);
    s.stageStates[0][D3DTSS_BUMPENVLOFFSET] = floatBits(0.25f);
    s.stageStates[1][D3DTSS_BUMPENVLSCALE] = floatBits(0.0f);  // not the one D3D9 uses
    s.stageStates[1][D3DTSS_BUMPENVLOFFSET] = floatBits(1.0f);
    setStage(s, 1, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0);
    std::vector<Pixel> px(4);
    for (int k = 0; k < 4; ++k) px[size_t(k)].u = 0.125f + 0.25f * float(k);
    // factor L·0.5 + 0.25: 0.75, 0.50098, 0.25, 0.75 times (200, 100, 40, 255), rounded once:
    // (150, 75, 30, 191.25 -> 191), (100.2 -> 100, 50.1 -> 50, 20.04 -> 20, 127.75 -> 128),
    // (50, 25, 10, 63.75 -> 64).
    const Outputs o = run(s, px, Precision::Fx8, &sampler);
    CHECK(o.grid[0] == Rgba{150, 75, 30, 191});
    CHECK(o.grid[1] == Rgba{100, 50, 20, 128});
    CHECK(o.grid[2] == Rgba{50, 25, 10, 64});
    CHECK(o.grid[3] == Rgba{150, 75, 30, 191});
}

TEST_CASE("ffp: program shape", "[ffp]") {
    DeviceState s;  // defaults: tex t0; mul_sat r0.rgb, t0, v0 + mov_sat r0.a, t0
    LoweredStages l = lower(s);
    const auto& ins = l.program.instructions;
    CHECK(l.program.version == ps11::Version{1, 1});
    REQUIRE(ins.size() == 3);
    CHECK(ins[0].opcode() == ps11::Opcode::Tex);
    CHECK(ins[1].opcode() == ps11::Opcode::Mul);
    CHECK(ins[1].dst.mask == ps11::kMaskRGB);
    CHECK(ins[1].dst.saturate);
    CHECK(ins[2].opcode() == ps11::Opcode::Mov);
    CHECK(ins[2].coissue);
    CHECK(ins[2].dst.mask == ps11::kMaskA);
    CHECK(l.sampledStages == 1u);
    CHECK(l.activeStages == 1);

    // Identical halves become one full-mask instruction.
    setStage(s, 0, D3DTOP_MODULATE, D3DTA_TEXTURE, D3DTA_DIFFUSE, D3DTOP_MODULATE, D3DTA_TEXTURE, D3DTA_DIFFUSE);
    l = lower(s);
    REQUIRE(l.program.instructions.size() == 2);
    CHECK(l.program.instructions[1].dst.mask == ps11::kMaskAll);

    // Deterministic, and the executor samples exactly the stages the lowering reports.
    setStage(s, 1, D3DTOP_BLENDTEXTUREALPHA, D3DTA_CURRENT, D3DTA_TFACTOR, D3DTOP_ADD, D3DTA_TEMP, D3DTA_CONSTANT);
    setStage(s, 2, D3DTOP_LERP, D3DTA_TEXTURE, D3DTA_CURRENT, D3DTOP_SELECTARG2, D3DTA_TEXTURE, D3DTA_CURRENT);
    s.renderStates[D3DRS_SPECULARENABLE] = 1;
    l = lower(s);
    CHECK(ps11::disassemble(l.program) == ps11::disassemble(lower(s).program));
    ps11::Diagnostics diags;
    auto ex = ps11::Executor::create(l.program, {}, diags);
    REQUIRE(ex);
    CHECK(ex->sampledStages() == l.sampledStages);
    CHECK(l.sampledStages == 7u);
    for (const ps11::Instruction& i : l.program.instructions) {
        if (i.opcode() == ps11::Opcode::Def) continue;
        if (i.info->cls == ps11::OpClass::Texture) continue;
        CHECK(i.dst.type == ps11::RegType::Temp);
        CHECK(i.dst.index < 2);
    }
}

TEST_CASE("ffp: errors name the stage and the state", "[ffp]") {
    auto fails = [](const DeviceState& s, const std::string& code, const std::string& prefix) {
        CallError error;
        CHECK_FALSE(lowerFixedFunction(s, error));
        INFO(error.code + " " + error.message);
        CHECK(error.hr == D3DERR_INVALIDCALL);
        CHECK(error.code == code);
        CHECK(error.message.rfind(prefix, 0) == 0);
    };
    DeviceState s;
    s.stageStates[0][D3DTSS_COLOROP] = 27;
    fails(s, "E4140", "stage 0 D3DTSS_COLOROP: unknown texture operation 27");
    s = DeviceState();
    s.stageStates[0][D3DTSS_COLOROP] = 0;
    fails(s, "E4140", "stage 0 D3DTSS_COLOROP:");
    s = DeviceState();
    s.stageStates[0][D3DTSS_ALPHAOP] = 0x7fffffff;
    fails(s, "E4140", "stage 0 D3DTSS_ALPHAOP:");

    s = DeviceState();
    s.stageStates[0][D3DTSS_COLORARG2] = 7;
    fails(s, "E4141", "stage 0 D3DTSS_COLORARG2: unknown texture argument 0x00000007");
    s = DeviceState();
    s.stageStates[0][D3DTSS_ALPHAARG1] = D3DTA_TEXTURE | 0x40;
    fails(s, "E4141", "stage 0 D3DTSS_ALPHAARG1:");
    s = DeviceState();
    setStage(s, 0, D3DTOP_LERP, D3DTA_TEXTURE, D3DTA_DIFFUSE, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0);
    s.stageStates[0][D3DTSS_COLORARG0] = 9;
    fails(s, "E4141", "stage 0 D3DTSS_COLORARG0:");
    // An argument the operation does not read is not checked.
    s = DeviceState();
    setStage(s, 0, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 9, D3DTOP_SELECTARG2, 9, D3DTA_DIFFUSE);
    CallError error;
    CHECK(lowerFixedFunction(s, error));

    // Texture reads beyond the sampled-stage limit.
    s = DeviceState();
    for (int i = 0; i < 4; ++i)
        setStage(s, i, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
    CHECK(lowerFixedFunction(s, error));
    setStage(s, 4, D3DTOP_MODULATE, D3DTA_CURRENT, D3DTA_TEXTURE, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
    fails(s, "E4142", "stage 4 D3DTSS_COLORARG2:");
    setStage(s, 4, D3DTOP_BLENDTEXTUREALPHA, D3DTA_CURRENT, D3DTA_DIFFUSE, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
    fails(s, "E4142", "stage 4 D3DTSS_COLOROP:");
    setStage(s, 4, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0, D3DTOP_SELECTARG1, D3DTA_TEXTURE, 0);
    fails(s, "E4142", "stage 4 D3DTSS_ALPHAARG1:");
    setStage(s, 4, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
    setStage(s, 3, D3DTOP_BUMPENVMAP, D3DTA_TEXTURE, 0, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
    fails(s, "E4142", "stage 3 D3DTSS_COLOROP: D3DTOP_BUMPENVMAP looks up stage 4's texture");

    // BUMPENVMAP in the last enabled stage.
    s = DeviceState();
    s.stageStates[0][D3DTSS_COLOROP] = D3DTOP_BUMPENVMAP;
    fails(s, "E4143", "stage 0 D3DTSS_COLOROP:");
    s.stageStates[0][D3DTSS_COLOROP] = D3DTOP_BUMPENVMAPLUMINANCE;
    fails(s, "E4143", "stage 0 D3DTSS_COLOROP:");

    // Colour-only operations as ALPHAOP.
    for (DWORD op : {D3DTOP_MODULATEALPHA_ADDCOLOR, D3DTOP_MODULATECOLOR_ADDALPHA, D3DTOP_MODULATEINVALPHA_ADDCOLOR,
                     D3DTOP_MODULATEINVCOLOR_ADDALPHA, D3DTOP_BUMPENVMAP, D3DTOP_BUMPENVMAPLUMINANCE}) {
        s = DeviceState();
        s.stageStates[0][D3DTSS_ALPHAOP] = op;
        fails(s, "E4144", "stage 0 D3DTSS_ALPHAOP:");
    }

    // PREMODULATE in stage 3 needs stage 4's texture.
    s = DeviceState();
    for (int i = 0; i < 5; ++i)
        setStage(s, i, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
    CHECK(lowerFixedFunction(s, error));
    s.stageStates[3][D3DTSS_ALPHAOP] = D3DTOP_PREMODULATE;
    fails(s, "E4142", "stage 3 D3DTSS_ALPHAOP: D3DTOP_PREMODULATE modulates with stage 4's texture");
    s.stageStates[3][D3DTSS_COLOROP] = D3DTOP_PREMODULATE;
    fails(s, "E4142", "stage 3 D3DTSS_COLOROP: D3DTOP_PREMODULATE");

    s = DeviceState();
    s.stageStates[0][D3DTSS_RESULTARG] = D3DTA_TEXTURE;
    fails(s, "E4146", "stage 0 D3DTSS_RESULTARG:");
    s.stageStates[0][D3DTSS_RESULTARG] = D3DTA_CURRENT | D3DTA_COMPLEMENT;
    fails(s, "E4146", "stage 0 D3DTSS_RESULTARG:");

    // Nine distinct constants: TFACTOR and eight per-stage CONSTANTs.
    s = DeviceState();
    for (int i = 0; i < kMaxStages; ++i) {
        setStage(s, i, D3DTOP_ADD, D3DTA_CURRENT, D3DTA_CONSTANT, D3DTOP_SELECTARG1, D3DTA_CURRENT, 0);
        s.stageStates[size_t(i)][D3DTSS_CONSTANT] = 0x01010101u * DWORD(i + 1);
    }
    CHECK(lowerFixedFunction(s, error));
    s.stageStates[0][D3DTSS_COLORARG1] = D3DTA_TFACTOR;
    fails(s, "E4147", "stage 7 D3DTSS_COLORARG2:");
}
