// Device stage: the state struct. Direct3D 9's documented defaults for every render, texture
// stage and sampler state (the D3DRENDERSTATETYPE / D3DTEXTURESTAGESTATETYPE /
// D3DSAMPLERSTATETYPE reference pages; Wine's stateblock defaults agree), plus hash/equality.
#include "emu/state.h"

#include <bit>
#include <vector>

namespace emu {

DWORD floatBits(float f) { return std::bit_cast<DWORD>(f); }
float bitsFloat(DWORD bits) { return std::bit_cast<float>(bits); }

bool isRenderState(DWORD s) {
    // d3d9types.h: 7-9, 14-16, 19-20, 22-29, 34-38, 48, 52-60, 128-137, 139-143, 145-148, 151-152,
    // 154-163, 165-168, 170-176, 178-195, 198-209.
    auto in = [s](DWORD a, DWORD b) { return s >= a && s <= b; };
    return in(7, 9) || in(14, 16) || in(19, 20) || in(22, 29) || in(34, 38) || s == 48 || in(52, 60) || in(128, 137) ||
           in(139, 143) || in(145, 148) || in(151, 152) || in(154, 163) || in(165, 168) || in(170, 176) ||
           in(178, 195) || in(198, 209);
}

bool isStageState(DWORD s) { return (s >= 1 && s <= 11) || (s >= 22 && s <= 24) || (s >= 26 && s <= 28) || s == 32; }

bool isSamplerState(DWORD s) { return s >= 1 && s <= 13; }

bool isFloatRenderState(DWORD s) {
    switch (s) {
        case D3DRS_FOGSTART:
        case D3DRS_FOGEND:
        case D3DRS_FOGDENSITY:
        case D3DRS_POINTSIZE:
        case D3DRS_POINTSIZE_MIN:
        case D3DRS_POINTSCALE_A:
        case D3DRS_POINTSCALE_B:
        case D3DRS_POINTSCALE_C:
        case D3DRS_POINTSIZE_MAX:
        case D3DRS_TWEENFACTOR:
        case D3DRS_SLOPESCALEDEPTHBIAS:
        case D3DRS_MINTESSELLATIONLEVEL:
        case D3DRS_MAXTESSELLATIONLEVEL:
        case D3DRS_ADAPTIVETESS_X:
        case D3DRS_ADAPTIVETESS_Y:
        case D3DRS_ADAPTIVETESS_Z:
        case D3DRS_ADAPTIVETESS_W:
        case D3DRS_DEPTHBIAS:
            return true;
        default:
            return false;
    }
}

bool isFloatStageState(DWORD s) {
    return (s >= D3DTSS_BUMPENVMAT00 && s <= D3DTSS_BUMPENVMAT11) || s == D3DTSS_BUMPENVLSCALE ||
           s == D3DTSS_BUMPENVLOFFSET;
}

DeviceState::DeviceState() {
    auto rs = [this](D3DRENDERSTATETYPE s, DWORD v) { renderStates[s] = v; };
    auto rsf = [this](D3DRENDERSTATETYPE s, float v) { renderStates[s] = floatBits(v); };
    // D3DZB_TRUE only with an automatic depth buffer (EnableAutoDepthStencil); this device has
    // none, so FALSE.
    rs(D3DRS_ZENABLE, D3DZB_FALSE);
    rs(D3DRS_FILLMODE, D3DFILL_SOLID);
    rs(D3DRS_SHADEMODE, D3DSHADE_GOURAUD);
    rs(D3DRS_ZWRITEENABLE, 1);
    rs(D3DRS_ALPHATESTENABLE, 0);
    rs(D3DRS_LASTPIXEL, 1);
    rs(D3DRS_SRCBLEND, D3DBLEND_ONE);
    rs(D3DRS_DESTBLEND, D3DBLEND_ZERO);
    rs(D3DRS_CULLMODE, D3DCULL_CCW);
    rs(D3DRS_ZFUNC, D3DCMP_LESSEQUAL);
    rs(D3DRS_ALPHAREF, 0);
    rs(D3DRS_ALPHAFUNC, D3DCMP_ALWAYS);
    rs(D3DRS_DITHERENABLE, 0);
    rs(D3DRS_ALPHABLENDENABLE, 0);
    rs(D3DRS_FOGENABLE, 0);
    rs(D3DRS_SPECULARENABLE, 0);
    rs(D3DRS_FOGCOLOR, 0);
    rs(D3DRS_FOGTABLEMODE, D3DFOG_NONE);
    rsf(D3DRS_FOGSTART, 0.0f);
    rsf(D3DRS_FOGEND, 1.0f);
    rsf(D3DRS_FOGDENSITY, 1.0f);
    rs(D3DRS_RANGEFOGENABLE, 0);
    rs(D3DRS_STENCILENABLE, 0);
    rs(D3DRS_STENCILFAIL, D3DSTENCILOP_KEEP);
    rs(D3DRS_STENCILZFAIL, D3DSTENCILOP_KEEP);
    rs(D3DRS_STENCILPASS, D3DSTENCILOP_KEEP);
    rs(D3DRS_STENCILFUNC, D3DCMP_ALWAYS);
    rs(D3DRS_STENCILREF, 0);
    rs(D3DRS_STENCILMASK, 0xFFFFFFFF);
    rs(D3DRS_STENCILWRITEMASK, 0xFFFFFFFF);
    rs(D3DRS_TEXTUREFACTOR, 0xFFFFFFFF);
    for (DWORD s = D3DRS_WRAP0; s <= D3DRS_WRAP7; ++s) renderStates[s] = 0;
    rs(D3DRS_CLIPPING, 1);
    rs(D3DRS_LIGHTING, 1);
    rs(D3DRS_AMBIENT, 0);
    rs(D3DRS_FOGVERTEXMODE, D3DFOG_NONE);
    rs(D3DRS_COLORVERTEX, 1);
    rs(D3DRS_LOCALVIEWER, 1);
    rs(D3DRS_NORMALIZENORMALS, 0);
    rs(D3DRS_DIFFUSEMATERIALSOURCE, D3DMCS_COLOR1);
    rs(D3DRS_SPECULARMATERIALSOURCE, D3DMCS_COLOR2);
    rs(D3DRS_AMBIENTMATERIALSOURCE, D3DMCS_MATERIAL);
    rs(D3DRS_EMISSIVEMATERIALSOURCE, D3DMCS_MATERIAL);
    rs(D3DRS_VERTEXBLEND, 0);  // D3DVBF_DISABLE
    rs(D3DRS_CLIPPLANEENABLE, 0);
    rsf(D3DRS_POINTSIZE, 1.0f);
    rsf(D3DRS_POINTSIZE_MIN, 1.0f);
    rs(D3DRS_POINTSPRITEENABLE, 0);
    rs(D3DRS_POINTSCALEENABLE, 0);
    rsf(D3DRS_POINTSCALE_A, 1.0f);
    rsf(D3DRS_POINTSCALE_B, 0.0f);
    rsf(D3DRS_POINTSCALE_C, 0.0f);
    rs(D3DRS_MULTISAMPLEANTIALIAS, 1);
    rs(D3DRS_MULTISAMPLEMASK, 0xFFFFFFFF);
    rs(D3DRS_PATCHEDGESTYLE, D3DPATCHEDGE_DISCRETE);
    rs(D3DRS_DEBUGMONITORTOKEN, D3DDMT_ENABLE);
    rsf(D3DRS_POINTSIZE_MAX, 64.0f);
    rs(D3DRS_INDEXEDVERTEXBLENDENABLE, 0);
    rs(D3DRS_COLORWRITEENABLE, 0xF);
    rsf(D3DRS_TWEENFACTOR, 0.0f);
    rs(D3DRS_BLENDOP, D3DBLENDOP_ADD);
    rs(D3DRS_POSITIONDEGREE, D3DDEGREE_CUBIC);
    rs(D3DRS_NORMALDEGREE, D3DDEGREE_LINEAR);
    rs(D3DRS_SCISSORTESTENABLE, 0);
    rsf(D3DRS_SLOPESCALEDEPTHBIAS, 0.0f);
    rs(D3DRS_ANTIALIASEDLINEENABLE, 0);
    rsf(D3DRS_MINTESSELLATIONLEVEL, 1.0f);
    rsf(D3DRS_MAXTESSELLATIONLEVEL, 1.0f);
    rsf(D3DRS_ADAPTIVETESS_X, 0.0f);
    rsf(D3DRS_ADAPTIVETESS_Y, 0.0f);
    rsf(D3DRS_ADAPTIVETESS_Z, 1.0f);
    rsf(D3DRS_ADAPTIVETESS_W, 0.0f);
    rs(D3DRS_ENABLEADAPTIVETESSELLATION, 0);
    rs(D3DRS_TWOSIDEDSTENCILMODE, 0);
    rs(D3DRS_CCW_STENCILFAIL, D3DSTENCILOP_KEEP);
    rs(D3DRS_CCW_STENCILZFAIL, D3DSTENCILOP_KEEP);
    rs(D3DRS_CCW_STENCILPASS, D3DSTENCILOP_KEEP);
    rs(D3DRS_CCW_STENCILFUNC, D3DCMP_ALWAYS);
    rs(D3DRS_COLORWRITEENABLE1, 0xF);
    rs(D3DRS_COLORWRITEENABLE2, 0xF);
    rs(D3DRS_COLORWRITEENABLE3, 0xF);
    rs(D3DRS_BLENDFACTOR, 0xFFFFFFFF);
    rs(D3DRS_SRGBWRITEENABLE, 0);
    rsf(D3DRS_DEPTHBIAS, 0.0f);
    for (DWORD s = D3DRS_WRAP8; s <= D3DRS_WRAP15; ++s) renderStates[s] = 0;
    rs(D3DRS_SEPARATEALPHABLENDENABLE, 0);
    rs(D3DRS_SRCBLENDALPHA, D3DBLEND_ONE);
    rs(D3DRS_DESTBLENDALPHA, D3DBLEND_ZERO);
    rs(D3DRS_BLENDOPALPHA, D3DBLENDOP_ADD);

    for (int i = 0; i < kMaxStages; ++i) {
        auto& t = stageStates[size_t(i)];
        // Stage 0 modulates texture by diffuse and takes the texture's alpha; every other stage
        // starts disabled (D3DTEXTURESTAGESTATETYPE reference page).
        t[D3DTSS_COLOROP] = i == 0 ? D3DTOP_MODULATE : D3DTOP_DISABLE;
        t[D3DTSS_COLORARG1] = D3DTA_TEXTURE;
        t[D3DTSS_COLORARG2] = D3DTA_CURRENT;
        t[D3DTSS_ALPHAOP] = i == 0 ? D3DTOP_SELECTARG1 : D3DTOP_DISABLE;
        t[D3DTSS_ALPHAARG1] = D3DTA_TEXTURE;
        t[D3DTSS_ALPHAARG2] = D3DTA_CURRENT;
        for (DWORD s = D3DTSS_BUMPENVMAT00; s <= D3DTSS_BUMPENVMAT11; ++s) t[s] = floatBits(0.0f);
        t[D3DTSS_TEXCOORDINDEX] = DWORD(i);  // stage i uses coordinate set i
        t[D3DTSS_BUMPENVLSCALE] = floatBits(0.0f);
        t[D3DTSS_BUMPENVLOFFSET] = floatBits(0.0f);
        t[D3DTSS_TEXTURETRANSFORMFLAGS] = D3DTTFF_DISABLE;
        t[D3DTSS_COLORARG0] = D3DTA_CURRENT;
        t[D3DTSS_ALPHAARG0] = D3DTA_CURRENT;
        t[D3DTSS_RESULTARG] = D3DTA_CURRENT;
        t[D3DTSS_CONSTANT] = 0;
    }
    for (auto& s : samplerStates) {
        s[D3DSAMP_ADDRESSU] = D3DTADDRESS_WRAP;
        s[D3DSAMP_ADDRESSV] = D3DTADDRESS_WRAP;
        s[D3DSAMP_ADDRESSW] = D3DTADDRESS_WRAP;
        s[D3DSAMP_BORDERCOLOR] = 0;  // 0x00000000
        s[D3DSAMP_MAGFILTER] = D3DTEXF_POINT;
        s[D3DSAMP_MINFILTER] = D3DTEXF_POINT;
        s[D3DSAMP_MIPFILTER] = D3DTEXF_NONE;
        s[D3DSAMP_MIPMAPLODBIAS] = floatBits(0.0f);
        s[D3DSAMP_MAXMIPLEVEL] = 0;
        s[D3DSAMP_MAXANISOTROPY] = 1;
        s[D3DSAMP_SRGBTEXTURE] = 0;
        s[D3DSAMP_ELEMENTINDEX] = 0;
        s[D3DSAMP_DMAPOFFSET] = 0;
    }
}

float DeviceState::renderStateFloat(D3DRENDERSTATETYPE s) const { return bitsFloat(renderStates[s]); }
float DeviceState::stageStateFloat(int stage, D3DTEXTURESTAGESTATETYPE s) const {
    return bitsFloat(stageStates[size_t(stage)][s]);
}

size_t DeviceState::hash(uint32_t parts) const {
    // FNV-1a over the words' bytes, 64-bit.
    uint64_t h = 1469598103934665603ull;
    forEachWord(
        [&h](uint32_t w) {
            for (int i = 0; i < 4; ++i) {
                h ^= (w >> (8 * i)) & 0xff;
                h *= 1099511628211ull;
            }
        },
        parts);
    return size_t(h);
}

bool DeviceState::equal(const DeviceState& other, uint32_t parts) const {
    std::vector<uint32_t> a;
    forEachWord([&a](uint32_t w) { a.push_back(w); }, parts);
    size_t i = 0;
    bool same = true;
    other.forEachWord([&](uint32_t w) { same = same && i < a.size() && a[i++] == w; }, parts);
    return same && i == a.size();
}

}  // namespace emu
