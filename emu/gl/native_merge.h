// The GL renderer's native mode (emu/gl/glsl.h FragmentSpec::native): the D3D9 output merger's
// blending, colour write mask and depth test as GL fixed-function state, the way a driver, Wine
// or DXVK runs them. Vertex fog and the alpha test, which GL core has not, stay in the fragment
// shader (glsl.cpp); the stencil test is not part of the emulator's merger.
#pragma once

#include <array>

#include "emu/gl/functions.h"
#include "emu/output_merger.h"

namespace emu::gl {

struct NativeMerge {
    bool blend = false;  // GL_BLEND
    // glBlendFuncSeparate(srcRgb, dstRgb, srcAlpha, dstAlpha)
    GLenum srcRgb = GL_ONE, dstRgb = GL_ZERO, srcAlpha = GL_ONE, dstAlpha = GL_ZERO;
    // glBlendEquationSeparate(eqRgb, eqAlpha)
    GLenum eqRgb = GL_FUNC_ADD, eqAlpha = GL_FUNC_ADD;
    // glBlendColor: D3DRS_BLENDFACTOR's bytes r g b a / 255 (GL_CONSTANT_COLOR's source)
    std::array<float, 4> blendColor{1.0f, 1.0f, 1.0f, 1.0f};
    // glColorMask r g b a: D3DRS_COLORWRITEENABLE, less the channels a blend leaves unchanged
    // (0·src + 1·dst: D3D9 keeps the target bit for bit, GL would compute 0·NaN and 0·∞ too)
    std::array<bool, 4> colorMask{true, true, true, true};
    bool depthTest = false;      // GL_DEPTH_TEST (ZENABLE with a depth surface)
    GLenum depthFunc = GL_LEQUAL;  // glDepthFunc (ZFUNC)
    bool depthWrite = false;     // glDepthMask (ZWRITEENABLE; nothing is written without the test)
    // GL_DEPTH_CLAMP: pre-transformed D3D9 vertices are not clipped against z, and the merger
    // compares z clamped to [0, 1]; GL clips at the near and far planes unless clamping.
    bool depthClamp = true;
    // True when every factor and operation of the draw has a GL counterpart of the same formula
    // taken as is; false when nativeMergeOf had to rewrite the state: BOTHSRCALPHA /
    // BOTHINVSRCALPHA (a pair of factors in one D3D9 value), a BOTH* value as a destination
    // factor, or an unknown D3DBLEND / D3DBLENDOP / D3DCMPFUNC value (replaced by its default).
    bool exact = true;
};

// The GL state of `m`'s blending, write mask and depth test; the depth test only when `hasDepth`
// (a depth surface is bound). Pure: no GL call.
NativeMerge nativeMergeOf(const MergeState& m, bool hasDepth);

// Sets `n` on the current context: GL_BLEND, glBlendFuncSeparate, glBlendEquationSeparate,
// glBlendColor, glColorMask, GL_DEPTH_TEST, glDepthFunc, glDepthMask and GL_DEPTH_CLAMP.
void applyNativeMerge(const GlFunctions& gl, const NativeMerge& n);

}  // namespace emu::gl
