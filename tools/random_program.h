// Random valid ps_1_1 … ps_1_4 programs, each inside a complete .ps11test (its textures,
// samplers, bump stages, constants and one full-target draw, no probes), and a shrinker that
// reduces a case while a predicate still holds: the generator and the reducer of differential
// fuzzing, where the emu device and the GL renderer draw the same file and their images are compared.
#pragma once

#include <functional>
#include <random>
#include <string>
#include <vector>

namespace ps11tools {

struct RandomCaseOptions {
    int minor = 0;     // 1..4 = that ps_1_x version; 0 = pick one at random per case
    int maxArith = 6;  // most arithmetic instructions (the version's slot limit still applies)
    int width = 8, height = 8;  // the render target of the generated draw
};

struct RandomCase {
    int minor = 1;
    std::vector<std::string> lines;  // the shader body, one instruction (or def) per line, without the ps_1_x line
    std::string shaderText() const;  // "ps_1_x\n" + lines joined with '\n'
    // A complete .ps11test: [require], [render target] (width × height), a [texture N] and
    // [sampler N] for every stage the shader samples (random texels, formats, filters and
    // address modes; V8U8 only on the stages that feed texbem, texbeml or bem), [stage N] bump
    // matrices where texbem, texbeml or bem read them, c0..c7 in [constants], the [pixel shader],
    // and one `draw triangles xyzrhw` of a full-target quad with random per-vertex colours and
    // texture coordinates.
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
// (isCleanProgram) and stillFails(candidate) holds, until no change is kept. A candidate's
// testText is caseTestText of it. Returns the smallest case found (start itself when nothing
// could be removed or simplified).
RandomCase shrinkCase(const RandomCase& start, const std::function<bool(const RandomCase&)>& stillFails);

}  // namespace ps11tools
