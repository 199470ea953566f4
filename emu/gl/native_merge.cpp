// Native mode's merge state (emu/gl/native_merge.h): D3D9 render states → GL blend and depth state.
//
// The D3D9 facts relied on (Microsoft's Direct3D 9 reference, "D3DBLEND", "D3DBLENDOP" and
// "D3DCMPFUNC", learn.microsoft.com/windows/win32/direct3d9/d3dblend, …/d3dblendop,
// …/d3dcmpfunc; the emulator's reading of them is docs/output-merger.md "Alpha blending"):
// - D3DBLEND factors are per channel (r, g, b, a) exactly as GL's: SRCCOLOR (Rs, Gs, Bs, As),
//   SRCALPHA (As, As, As, As), DESTCOLOR (Rd, Gd, Bd, Ad), DESTALPHA (Ad, …), the INV* forms
//   1 − the same, SRCALPHASAT (f, f, f, 1) with f = min(As, 1 − Ad) — GL_SRC_ALPHA_SATURATE's
//   definition —, BLENDFACTOR / INVBLENDFACTOR the D3DRS_BLENDFACTOR colour (its alpha byte
//   for alpha) = GL_CONSTANT_COLOR / GL_ONE_MINUS_CONSTANT_COLOR with glBlendColor.
// - D3DBLEND_BOTHSRCALPHA (obsolete, SRCBLEND only): source (As, As, As, As), destination
//   (1 − As, …), "the destination blend selection is overridden"; BOTHINVSRCALPHA the reverse.
//   GL has no pair factor: they become GL_SRC_ALPHA / GL_ONE_MINUS_SRC_ALPHA and
//   GL_ONE_MINUS_SRC_ALPHA / GL_SRC_ALPHA. As a destination factor (undefined in D3D9) each is
//   the destination half of its pair, as the emulator's merger decides (output_merger.cpp).
// - D3DBLENDOP: ADD s·Fs + d·Fd, SUBTRACT s·Fs − d·Fd, REVSUBTRACT d·Fd − s·Fs, MIN min(s, d),
//   MAX max(s, d): GL_FUNC_ADD, GL_FUNC_SUBTRACT, GL_FUNC_REVERSE_SUBTRACT, GL_MIN, GL_MAX.
//   MIN and MAX ignore the factors in both APIs.
// - Without D3DRS_SEPARATEALPHABLENDENABLE alpha blends with SRCBLEND, DESTBLEND and BLENDOP.
// - D3DCMPFUNC compares the new pixel's value with the stored one ("accept the new pixel if its
//   value is less than the value of the current pixel"), GL's depth test likewise: NEVER, LESS,
//   EQUAL, LESSEQUAL, GREATER, NOTEQUAL, GREATEREQUAL, ALWAYS = GL_NEVER … GL_ALWAYS.
// - Unknown values act as the state's default (MergeState::from, makePlan): ONE, ZERO, ADD,
//   LESSEQUAL.
// GL 4.x core accepts GL_SRC_ALPHA_SATURATE as a destination factor (GL 2.x did not); the
// renderer needs 4.5.
#include "emu/gl/native_merge.h"

namespace emu::gl {

namespace {

bool knownBlend(DWORD b) { return b >= D3DBLEND_ZERO && b <= D3DBLEND_INVBLENDFACTOR; }
bool knownOp(DWORD o) { return o >= D3DBLENDOP_ADD && o <= D3DBLENDOP_MAX; }
bool knownCmp(DWORD c) { return c >= D3DCMP_NEVER && c <= D3DCMP_ALWAYS; }

// The GL factor of a D3D9 factor other than the BOTH* pair values.
GLenum glFactor(D3DBLEND b) {
    switch (b) {
        case D3DBLEND_ZERO:
            return GL_ZERO;
        case D3DBLEND_ONE:
            return GL_ONE;
        case D3DBLEND_SRCCOLOR:
            return GL_SRC_COLOR;
        case D3DBLEND_INVSRCCOLOR:
            return GL_ONE_MINUS_SRC_COLOR;
        case D3DBLEND_SRCALPHA:
            return GL_SRC_ALPHA;
        case D3DBLEND_INVSRCALPHA:
            return GL_ONE_MINUS_SRC_ALPHA;
        case D3DBLEND_DESTALPHA:
            return GL_DST_ALPHA;
        case D3DBLEND_INVDESTALPHA:
            return GL_ONE_MINUS_DST_ALPHA;
        case D3DBLEND_DESTCOLOR:
            return GL_DST_COLOR;
        case D3DBLEND_INVDESTCOLOR:
            return GL_ONE_MINUS_DST_COLOR;
        case D3DBLEND_SRCALPHASAT:
            return GL_SRC_ALPHA_SATURATE;
        case D3DBLEND_BLENDFACTOR:
            return GL_CONSTANT_COLOR;
        case D3DBLEND_INVBLENDFACTOR:
            return GL_ONE_MINUS_CONSTANT_COLOR;
        default:
            return GL_ZERO;  // BOTH* are resolved before
    }
}

GLenum glEquation(D3DBLENDOP o) {
    switch (o) {
        case D3DBLENDOP_SUBTRACT:
            return GL_FUNC_SUBTRACT;
        case D3DBLENDOP_REVSUBTRACT:
            return GL_FUNC_REVERSE_SUBTRACT;
        case D3DBLENDOP_MIN:
            return GL_MIN;
        case D3DBLENDOP_MAX:
            return GL_MAX;
        default:
            return GL_FUNC_ADD;
    }
}

GLenum glCompare(D3DCMPFUNC f) {
    switch (f) {
        case D3DCMP_NEVER:
            return GL_NEVER;
        case D3DCMP_LESS:
            return GL_LESS;
        case D3DCMP_EQUAL:
            return GL_EQUAL;
        case D3DCMP_LESSEQUAL:
            return GL_LEQUAL;
        case D3DCMP_GREATER:
            return GL_GREATER;
        case D3DCMP_NOTEQUAL:
            return GL_NOTEQUAL;
        case D3DCMP_GREATEREQUAL:
            return GL_GEQUAL;
        default:
            return GL_ALWAYS;
    }
}

// One blend (colour or alpha): the D3D9 factors and op, sanitised and with BOTH* resolved.
struct Blend {
    D3DBLEND src, dst;
    D3DBLENDOP op;
};

Blend resolve(DWORD src, DWORD dst, DWORD op, bool& exact) {
    Blend b{D3DBLEND_ONE, D3DBLEND_ZERO, D3DBLENDOP_ADD};
    if (knownBlend(src)) b.src = D3DBLEND(src);
    else exact = false;
    if (knownBlend(dst)) b.dst = D3DBLEND(dst);
    else exact = false;
    if (knownOp(op)) b.op = D3DBLENDOP(op);
    else exact = false;
    if (b.src == D3DBLEND_BOTHSRCALPHA) {
        b.src = D3DBLEND_SRCALPHA, b.dst = D3DBLEND_INVSRCALPHA, exact = false;
    } else if (b.src == D3DBLEND_BOTHINVSRCALPHA) {
        b.src = D3DBLEND_INVSRCALPHA, b.dst = D3DBLEND_SRCALPHA, exact = false;
    } else if (b.dst == D3DBLEND_BOTHSRCALPHA) {
        b.dst = D3DBLEND_INVSRCALPHA, exact = false;
    } else if (b.dst == D3DBLEND_BOTHINVSRCALPHA) {
        b.dst = D3DBLEND_SRCALPHA, exact = false;
    }
    return b;
}

// 0·src + 1·dst (ADD or REVSUBTRACT): the channel keeps the target.
bool keepsTarget(const Blend& b) {
    return b.src == D3DBLEND_ZERO && b.dst == D3DBLEND_ONE &&
           (b.op == D3DBLENDOP_ADD || b.op == D3DBLENDOP_REVSUBTRACT);
}

}  // namespace

NativeMerge nativeMergeOf(const MergeState& m, bool hasDepth) {
    NativeMerge n;
    for (int c = 0; c < 4; ++c) n.colorMask[size_t(c)] = ((m.colorWrite >> c) & 1u) != 0;
    n.blend = m.blend;
    if (m.blend) {
        bool exact = true;
        const Blend rgb = resolve(m.srcBlend, m.dstBlend, m.blendOp, exact);
        const Blend alpha =
            m.separateAlpha ? resolve(m.srcBlendAlpha, m.dstBlendAlpha, m.blendOpAlpha, exact) : rgb;
        n.srcRgb = glFactor(rgb.src), n.dstRgb = glFactor(rgb.dst), n.eqRgb = glEquation(rgb.op);
        n.srcAlpha = glFactor(alpha.src), n.dstAlpha = glFactor(alpha.dst), n.eqAlpha = glEquation(alpha.op);
        n.exact = exact;
        if (keepsTarget(rgb)) n.colorMask[0] = n.colorMask[1] = n.colorMask[2] = false;
        if (keepsTarget(alpha)) n.colorMask[3] = false;
    }
    // D3DCOLOR is 0xAARRGGBB.
    const D3DCOLOR bf = m.blendFactor;
    n.blendColor = {float((bf >> 16) & 0xffu) / 255.0f, float((bf >> 8) & 0xffu) / 255.0f, float(bf & 0xffu) / 255.0f,
                    float(bf >> 24) / 255.0f};
    n.depthTest = m.depthTest && hasDepth;
    n.depthWrite = n.depthTest && m.depthWrite;
    if (n.depthTest) {
        if (knownCmp(m.depthFunc)) {
            n.depthFunc = glCompare(m.depthFunc);
        } else {
            n.depthFunc = GL_LEQUAL;
            n.exact = false;
        }
    }
    return n;
}

void applyNativeMerge(const GlFunctions& gl, const NativeMerge& n) {
    if (n.blend) gl.Enable(GL_BLEND);
    else gl.Disable(GL_BLEND);
    gl.BlendFuncSeparate(n.srcRgb, n.dstRgb, n.srcAlpha, n.dstAlpha);
    gl.BlendEquationSeparate(n.eqRgb, n.eqAlpha);
    gl.BlendColor(n.blendColor[0], n.blendColor[1], n.blendColor[2], n.blendColor[3]);
    gl.ColorMask(n.colorMask[0] ? GL_TRUE : GL_FALSE, n.colorMask[1] ? GL_TRUE : GL_FALSE,
                 n.colorMask[2] ? GL_TRUE : GL_FALSE, n.colorMask[3] ? GL_TRUE : GL_FALSE);
    if (n.depthTest) gl.Enable(GL_DEPTH_TEST);
    else gl.Disable(GL_DEPTH_TEST);
    gl.DepthFunc(n.depthFunc);
    gl.DepthMask(n.depthWrite ? GL_TRUE : GL_FALSE);
    if (n.depthClamp) gl.Enable(GL_DEPTH_CLAMP);
    else gl.Disable(GL_DEPTH_CLAMP);
}

}  // namespace emu::gl
