// Random valid ps_1_1 … ps_1_4 programs, each inside a complete .ps11test (its textures,
// samplers, bump stages, render states, constants and one full-target draw, no probes), and a
// shrinker that reduces a case, program and environment, while a predicate still holds: the
// generator and the reducer of differential fuzzing, where the emu device and the GL renderer
// draw the same file and their images are compared.
#pragma once

#include <functional>
#include <random>
#include <string>
#include <vector>

namespace ps11test {

struct RandomCaseOptions {
    int minor = 0;              // 1..4 = that ps_1_x version; 0 = pick one at random per case
    int maxArith = 6;           // most arithmetic instructions (the version's slot limit still applies)
    int width = 8, height = 8;  // the render target of the generated draw
};

struct RandomCase {
    int minor = 1;
    std::vector<std::string> lines;  // the shader body, one instruction (or def) per line, without the ps_1_x line
    std::string shaderText() const;  // "ps_1_x\n" + lines joined with '\n'
    // A complete .ps11test: [require], [render target] (width × height), a [texture N] and
    // [sampler N] for every stage the shader samples, [stage N] bump matrices where texbem,
    // texbeml or bem read them, c0..c7 in [constants], the [pixel shader], and one `draw
    // triangles xyzrhw` of a full-target quad (corners half a pixel outside, the 1:1 mapping of
    // `draw quad`) with random per-vertex colours and texture coordinates.
    //
    // randomCase draws the whole environment the renderers must agree on, each feature on its
    // own with a probability of 15-45 % so that a mismatch points at few of them:
    // - [require] a hardware class that runs the version (35 %), a precision profile (25 %);
    // - the target A16B16G16R16F or A32B32G32R32F (35 %) or X8R8G8B8; a D24S8 depth buffer
    //   with a random clear (40 %), then z varies over the vertices, and zfunc / zwrite off;
    // - textures of every format (signed ones mostly on the stages texbem, texbeml or bem read
    //   as offsets, float ones with float texels), 1 … 16 texels a side (sometimes not a power
    //   of two), volumes (30 %), mip chains (45 %: `levels 0` generated, or 2 … all levels
    //   given, a level sometimes a `fill`), min and mag filters drawn apart, mip none / point /
    //   linear, every address mode with mirroronce, U V and W;
    // - [render state] alpha blending with any factors, operation and blend factor (35 %), an
    //   alpha test (30 %), vertex fog (30 %), a colour write mask (25 %);
    // - perspective: rhw varying over the vertices (40 %); coordinates over [-k, k + 1], k = 1, 2
    //   or 4 (45 %), so textures are minified; 1 … 3 random overlapping triangles after the quad
    //   (40 %).
    // caseForProgram draws the plain environment only: one-level 2D textures (2 … 8 texels a
    // side, unsigned formats, V8U8 half the time on bump stages), point or linear, wrap, clamp,
    // mirror or border, the 8-bit target, no depth, no render states, rhw 1, u and v in
    // [-0.5, 1.5].
    std::string testText;
};

// A random program of ps_1_<minor> that assembles and validates without any diagnostic (no
// error, and no warning: warnings mark results D3D leaves undefined), with its test file.
// The same rng state gives the same case with every standard library.
RandomCase randomCase(std::mt19937_64& rng, const RandomCaseOptions& options);

// The random inputs of randomCase (textures of the formats the instructions need, samplers,
// bump stages, constants, the draw's colours and coordinates) around a given program: what
// `ps11 compare SHADER.psh` draws. The lines must assemble and validate as ps_1_<minor>
// (warnings allowed); otherwise testText is empty.
RandomCase caseForProgram(std::mt19937_64& rng, int minor, const std::vector<std::string>& lines,
                          const RandomCaseOptions& options);

// c.testText with its [pixel shader] block replaced by c.shaderText() (appended when the file
// has none): the same textures, states, constants and draw for a changed instruction list.
std::string caseTestText(const RandomCase& c);

// True when the lines, as ps_1_<minor>, assemble and validate (r0 written) without any
// diagnostic: what randomCase produces and shrinkCase keeps.
bool isCleanProgram(int minor, const std::vector<std::string>& lines);

// Delta-debugging reduction: removes runs of lines (every length from half the program down
// to single lines) and
// simplifies single instructions (replaces a source by c0 or v0, drops source modifiers and
// selectors, writes r0 instead of another register, drops the write mask, the co-issue '+',
// the shift and _sat), keeping each change for which the program stays clean
// (isCleanProgram) and stillFails(candidate) holds; then simplifies the environment the same
// way (the file outside its shader): leaves out whole sections (not [require], [render
// target], [pixel shader] or [test]), the draw's extra triangles, single keyword lines (not
// the version or the target's size) and the levels after 0 of a mip chain, and sets every
// vertex's rhw to 1 and z to 0, keeping each change whose file still parses and still fails.
// Both rounds repeat until no change is kept. A candidate's testText is caseTestText of it
// (the program's rounds) or the simplified file (the environment's). Returns the smallest
// case found (start itself when nothing could be removed or simplified).
RandomCase shrinkCase(const RandomCase& start, const std::function<bool(const RandomCase&)>& stillFails);

}  // namespace ps11test
