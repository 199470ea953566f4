// The GLSL writer's parts (emu/gl/glsl.cpp: the program; glsl_sampler.cpp: one sampling
// function per stage; glsl_merge.cpp: the output merger) and what they share. Not part of the
// renderer's interface (emu/gl/glsl.h).
#pragma once

#include <sstream>
#include <string>

#include "emu/gl/glsl.h"

namespace emu::gl::detail {

// What every part writes with: the spec, the decoded program's profile, whether the profile is
// fixed-point, and the shader text so far.
struct GlslContext {
    const FragmentSpec& spec;
    const ps11::exec::Profile& p;
    bool fx;
    std::ostringstream& o;
};

// The shader's register array R is the executor's register file (ps11/decoded_program.h):
// "R[slot]" for a slot of it (r# at kSlotR + #, t# at kSlotT + #, v# at kSlotV + #).
inline std::string regSlot(int slot) { return "R[" + std::to_string(slot) + "]"; }
// r0, the colour the merge takes.
inline std::string regR0() { return regSlot(ps11::exec::kSlotR + 0); }

// A double literal that reads back as `v` (17 significant digits, always with a point or exponent).
std::string num(double v);
// A float literal that reads back as exactly `v` (its bits through uintBitsToFloat).
std::string flit(float v);

// The sampling helpers (texel positions, address modes, level of detail, weights), in shaders
// that sample a texture.
extern const char* const kSampling;
// `ivec4 S<s>(float u, float v, float w)` (fx) or `vec4 S<s>(…)` (float profiles) for stage s.
void writeSampler(GlslContext& cx, int s);
// The merge's helper functions, then the merge at the end of main() (r0 in regR0()).
void writeMergeFunctions(GlslContext& cx);
void writeMerge(GlslContext& cx);

}  // namespace emu::gl::detail
