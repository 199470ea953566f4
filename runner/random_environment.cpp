// The test file around a random program (runner/random_program.h): the environment of
// randomCase drawn feature by feature as .ps11test text (docs/test-format.md), and the simpler
// environments the shrinker tries, as lines of that text.
#include "runner/random_case_internal.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdio>
#include <optional>

#include "ps11/assembler.h"
#include "ps11/disassembler.h"
#include "ps11/formats.h"
#include "ps11/hardware.h"
#include "ps11/ir.h"
#include "ps11/opcodes.h"
#include "ps11/testfile.h"
#include "ps11/token_format.h"
#include "ps11/validator.h"

namespace ps11test {

using ps11::Instruction;
using ps11::Opcode;
using ps11::RegType;

namespace {

// ---------------------------------------------------------------- the test file

// "0.125": a multiple of 1/1000 as the file writes it.
std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", v);
    return buf;
}

// "0x" and the word in `bits` / 4 hex digits.
std::string hexWord(uint32_t w, int bits = 32) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%0*x", bits / 4, w);
    return buf;
}

// Stages whose texels the program reads as signed bump offsets (the texture of t(n) in
// texbem/texbeml t(m), t(n); in ps_1_4 the texld of stage n that fills bem's second source rn),
// and stages whose bump matrix it reads (texbem/texbeml t(m): stage m; bem r(m): stage m).
struct BumpStages {
    uint32_t signedTexels = 0;
    uint32_t matrices = 0;
};

BumpStages bumpStagesOf(const ps11::Program& program) {
    BumpStages b;
    for (const Instruction& in : program.instructions) {
        const Opcode op = in.opcode();
        if (op == Opcode::TexBem || op == Opcode::TexBemL || op == Opcode::Bem) {
            b.signedTexels |= 1u << in.src[op == Opcode::Bem ? 1 : 0].index;
            b.matrices |= 1u << in.dst.index;
        }
    }
    return b;
}

// The plain texture of caseForProgram: one level, 2..8 texels a side, an unsigned format (V8U8
// on bump stages half the time), point or linear, wrap/clamp/mirror/border.
std::string plainTextureSection(Dice& dice, int stage, bool signedTexels) {
    using ps11::TexFormat;
    static const std::vector<TexFormat> kUnsigned = {TexFormat::A8R8G8B8, TexFormat::X8R8G8B8, TexFormat::L8,
                                                     TexFormat::A8L8};
    const TexFormat format = signedTexels && dice.chance(50) ? TexFormat::V8U8 : dice.pick(kUnsigned);
    const int width = 1 << dice.range(1, 3), height = 1 << dice.range(1, 3);
    const int bits = ps11::formatBits(format);
    std::string out = "[texture " + std::to_string(stage) + "]\nsize " + std::to_string(width) + " " +
                      std::to_string(height) + "\nformat " + ps11::texFormatName(format) + "\nlevel 0\n";
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const uint32_t texel = bits == 32 ? dice.word() : dice.word() & ((1u << bits) - 1);
            out += (x ? " " : "") + hexWord(texel, bits);
        }
        out += "\n";
    }
    static const std::vector<std::string> kAddress = {"wrap", "clamp", "mirror", "border"};
    const std::string u = dice.pick(kAddress), v = dice.pick(kAddress);
    out += "\n[sampler " + std::to_string(stage) + "]\nfilter " + (dice.chance(50) ? "point" : "linear") +
           "\naddress " + u + " " + v + "\n";
    if (u == "border" || v == "border") out += "border " + hexWord(dice.word()) + "\n";
    return out + "\n";
}

// ---- the whole environment of randomCase: each feature drawn on its own, with a probability
// (percent) that keeps a mismatch attributable to few of them.
constexpr int kHardwarePercent = 35;         // [require] hardware: a class that runs the version
constexpr int kPrecisionPercent = 25;        // [require] precision: fx8, fx12, float or ideal
constexpr int kFloatTargetPercent = 35;      // A16B16G16R16F or A32B32G32R32F render target
constexpr int kX8TargetPercent = 15;         // X8R8G8B8 (of the 8-bit targets)
constexpr int kDepthPercent = 40;            // depth on (D24S8), a random clear, zfunc, zwrite
constexpr int kPerspectivePercent = 40;      // rhw varies across the vertices
constexpr int kExtraTrianglesPercent = 40;   // 1..3 overlapping triangles after the quad
constexpr int kWideCoordinatesPercent = 45;  // u, v over [-k, k + 1], k = 1, 2, 4 (minification)
constexpr int kBlendPercent = 35;            // alphablend on, random factors, op and blend factor
constexpr int kAlphaTestPercent = 30;        // alphatest on FUNC REF
constexpr int kFogPercent = 30;              // vertex fog (specular alpha) with a random colour
constexpr int kColorWritePercent = 25;       // a colour write mask other than rgba
constexpr int kVolumePercent = 30;           // a sampled stage's texture is a volume
constexpr int kMipPercent = 45;              // a mip chain (levels 0 = generated, 2D only; or 2..all given)

using ps11::TexFormat;
// The texture formats of one class, in ps11::kFormatRows' order.
std::vector<TexFormat> formatsOf(ps11::FormatClass cls) {
    std::vector<TexFormat> out;
    for (size_t i = 0; i < ps11::kTexFormatCount; ++i)
        if (ps11::kFormatRows[i].cls == cls) out.push_back(TexFormat(i));
    return out;
}
const std::vector<TexFormat> kUnsignedFormats = formatsOf(ps11::FormatClass::Unorm8);
const std::vector<TexFormat> kSignedFormats = formatsOf(ps11::FormatClass::Signed);
const std::vector<TexFormat> kFloatFormats = formatsOf(ps11::FormatClass::Float);

const std::vector<std::string> kCompareFuncs = {"never",   "less",     "equal",        "lessequal",
                                                "greater", "notequal", "greaterequal", "always"};
const std::vector<std::string> kBlends = {
    "zero",        "one",          "srccolor",        "invsrccolor", "srcalpha",
    "invsrcalpha", "destalpha",    "invdestalpha",    "destcolor",   "invdestcolor",
    "srcalphasat", "bothsrcalpha", "bothinvsrcalpha", "blendfactor", "invblendfactor"};
const std::vector<std::string> kBlendOps = {"add", "subtract", "revsubtract", "min", "max"};

// A texture side: a power of two up to 2^maxLog2, or now and then one that is not.
int textureSide(Dice& dice, int maxLog2) {
    if (dice.chance(15)) {
        static const std::vector<int> kOther = {3, 5, 6, 7, 12};
        const int side = dice.pick(kOther);
        if (side <= 1 << maxLog2) return side;
    }
    return 1 << dice.range(0, maxLog2);
}

int levelSide(int side, int level) { return std::max(1, side >> level); }

int chainLength(int w, int h, int d) {
    int levels = 1;
    while (std::max({w, h, d}) >> levels) ++levels;
    return levels;
}

// One component of a float texel: mostly around [0, 1], sometimes far out, sometimes a value
// with a story (signed zero, the largest half, a tiny one).
std::string floatComponent(Dice& dice) {
    const int roll = dice.below(100);
    if (roll < 80) return number(dice.thousandths(-1.5, 2.5));
    if (roll < 95) return number(dice.thousandths(-40, 40));
    static const std::vector<std::string> kSpecial = {"0", "-0", "1", "-1", "0.5", "0.001", "-0.001", "1000", "65504"};
    return dice.pick(kSpecial);
}

std::string texelText(Dice& dice, TexFormat format) {
    if (!ps11::isFloatFormat(format)) {
        const int bits = ps11::formatBits(format);
        const uint32_t w = dice.word();
        return hexWord(bits == 32 ? w : w & ((1u << bits) - 1), bits);
    }
    const int count = format == TexFormat::R32F ? 1 : dice.chance(10) ? dice.range(1, 3) : 4;
    std::string out = "(";
    for (int c = 0; c < count; ++c) out += (c ? " " : "") + floatComponent(dice);
    return out + ")";
}

// `level K`, then its rows (height × depth of them, slice after slice) or a fill.
void appendLevel(std::string& out, Dice& dice, TexFormat format, int level, int w, int h, int d) {
    out += "level " + std::to_string(level) + "\n";
    if (level > 0 && dice.chance(20)) {
        out += "fill " + texelText(dice, format) + "\n";
        return;
    }
    for (int row = 0; row < h * d; ++row) {
        for (int x = 0; x < w; ++x) out += (x ? " " : "") + texelText(dice, format);
        out += "\n";
    }
}

// The [texture N] and [sampler N] of a sampled stage in randomCase: any format (signed ones
// more often on bump stages), 2D or volume, one level or a chain, min/mag/mip filters and
// every address mode.
std::string fullTextureSection(Dice& dice, int stage, bool signedTexels) {
    const int roll = dice.below(100);
    const int signedPercent = signedTexels ? 55 : 15, floatPercent = signedTexels ? 15 : 20;
    const TexFormat format = roll < signedPercent                  ? dice.pick(kSignedFormats)
                             : roll < signedPercent + floatPercent ? dice.pick(kFloatFormats)
                                                                   : dice.pick(kUnsignedFormats);
    const bool volume = dice.chance(kVolumePercent);
    const int width = textureSide(dice, volume ? 3 : 4), height = textureSide(dice, volume ? 3 : 4);
    const int depth = volume ? std::max(2, textureSide(dice, 3)) : 1;
    const int chain = chainLength(width, height, depth);
    int levels = 1;  // 0 = generated from level 0
    if (chain > 1 && dice.chance(kMipPercent)) levels = !volume && dice.chance(35) ? 0 : dice.range(2, chain);
    std::string out = "[texture " + std::to_string(stage) + "]\nsize " + std::to_string(width) + " " +
                      std::to_string(height) + (volume ? " " + std::to_string(depth) : std::string()) + "\nformat " +
                      ps11::texFormatName(format) + "\n";
    if (levels != 1) out += "levels " + std::to_string(levels) + "\n";
    for (int k = 0; k < std::max(1, levels); ++k)
        appendLevel(out, dice, format, k, levelSide(width, k), levelSide(height, k), volume ? levelSide(depth, k) : 1);

    static const std::vector<std::string> kFilters = {"point", "linear"};
    const std::string minFilter = dice.pick(kFilters), magFilter = dice.pick(kFilters);
    std::string mip = "none";
    if (levels != 1) {
        const int m = dice.below(100);
        mip = m < 20 ? "none" : m < 60 ? "point" : "linear";
    } else if (dice.chance(15)) {
        mip = dice.pick(kFilters);  // a mip filter over a single level
    }
    out += "\n[sampler " + std::to_string(stage) + "]\nfilter " + minFilter;
    if (magFilter != minFilter) out += " " + magFilter;
    if (mip != "none") out += " mip " + mip;
    static const std::vector<std::string> kAddress = {"wrap", "clamp", "mirror", "border", "mirroronce"};
    std::vector<std::string> modes = {dice.pick(kAddress), dice.pick(kAddress)};
    if (volume) modes.push_back(dice.pick(kAddress));
    out += "\naddress";
    for (const std::string& m : modes) out += " " + m;
    out += "\n";
    if (std::find(modes.begin(), modes.end(), "border") != modes.end()) out += "border " + hexWord(dice.word()) + "\n";
    return out + "\n";
}

// How randomCase draws beyond the program (all off for caseForProgram).
struct Environment {
    bool full = false;
    bool depth = false;
    bool perspective = false;
    int extraTriangles = 0;
    double coordinateLo = -0.5, coordinateHi = 1.5;  // u and v of the vertices
};

// One vertex line of `draw triangles xyzrhw` at (x, y): z (random with a depth buffer), rhw
// (random with perspective), diffuse, specular (its alpha is the fog factor) and every texture
// set of the version with four components; the third and fourth (the divisors of _dz and _dw)
// stay in [0.25, 1.5], away from zero.
std::string vertexLine(Dice& dice, const Environment& env, int minor, double x, double y) {
    std::string v = number(x) + " " + number(y);
    if (env.full)
        v += " " + number(env.depth ? dice.thousandths(0, 1) : 0) + " " +
             number(env.perspective ? dice.thousandths(0.1, 2) : 1) + " ";
    else
        v += " 0 1 ";
    v += hexWord(dice.word()) + " " + hexWord(dice.word());
    for (int t = 0; t < ps11::registerCount(RegType::Texture, minor); ++t) {
        v += " t" + std::to_string(t);
        for (int c = 0; c < 4; ++c)
            v += " " +
                 number(c < 2 ? dice.thousandths(env.coordinateLo, env.coordinateHi) : dice.thousandths(0.25, 1.5));
    }
    return v;
}

// The [render state] lines of randomCase (empty when it draws none of them).
std::string renderStateSection(Dice& dice, bool depth) {
    std::string out;
    if (dice.chance(kBlendPercent)) {
        const std::string src = dice.pick(kBlends), dst = dice.pick(kBlends);
        out += "alphablend on\nsrcblend " + src + "\ndestblend " + dst + "\n";
        if (!dice.chance(50)) out += "blendop " + dice.pick(kBlendOps) + "\n";
        if (src.find("blendfactor") != std::string::npos || dst.find("blendfactor") != std::string::npos ||
            dice.chance(20))
            out += "blendfactor " + hexWord(dice.word()) + "\n";
    }
    if (dice.chance(kAlphaTestPercent))
        out += "alphatest on " + dice.pick(kCompareFuncs) + " " + std::to_string(dice.below(256)) + "\n";
    if (dice.chance(kFogPercent)) out += "fog on " + hexWord(dice.word()) + "\n";
    if (depth) {
        // Mostly the functions that keep some pixels and reject others.
        static const std::vector<std::string> kUsual = {"less", "lessequal", "greater", "greaterequal"};
        out += "zfunc " + (dice.chance(70) ? dice.pick(kUsual) : dice.pick(kCompareFuncs)) + "\n";
        if (dice.chance(30)) out += "zwrite off\n";
    }
    if (dice.chance(kColorWritePercent)) {
        const int mask = dice.below(15);  // any but rgba
        std::string letters;
        for (int c = 0; c < 4; ++c)
            if (mask & (1 << c)) letters += "rgba"[c];
        out += "colorwrite " + (letters.empty() ? std::string("none") : letters) + "\n";
    }
    return out.empty() ? out : "[render state]\n" + out + "\n";
}


// ---------------------------------------------------------------- shrinking the environment

std::vector<std::string> splitLines(const std::string& text) {
    std::vector<std::string> lines;
    size_t begin = 0;
    while (begin < text.size()) {
        const size_t end = text.find('\n', begin);
        lines.push_back(text.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
        if (end == std::string::npos) break;
        begin = end + 1;
    }
    return lines;
}

std::string joinLines(const std::vector<std::string>& lines) {
    std::string text;
    for (const std::string& line : lines) text += line + "\n";
    return text;
}

std::vector<std::string> wordsOf(const std::string& line) {
    std::vector<std::string> words;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const size_t begin = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > begin) words.push_back(line.substr(begin, i - begin));
    }
    return words;
}

}  // namespace

// Everything but the shader: the file around `shader`, whose [pixel shader] block comes last
// before [test]. `full` draws randomCase's whole environment; otherwise caseForProgram's plain
// one (the same text, draw for draw, as before the environment existed).
std::string testTextOf(Dice& dice, const ps11::Program& program, const std::string& shader, int width, int height,
                       bool full) {
    const int minor = program.version.minor;
    std::string out = "% a random ps_1_" + std::to_string(minor) +
                      " case (runner/random_program.cpp): one draw, no probes\n[require]\nversion ps_1_" +
                      std::to_string(minor) + "\n";
    Environment env;
    env.full = full;
    if (full) {
        if (dice.chance(kHardwarePercent)) {
            std::vector<std::string> classes;
            for (const ps11::HardwareClass& h : ps11::hardwareClasses())
                if (h.maxMinor >= minor) classes.emplace_back(h.name);
            out += "hardware " + dice.pick(classes) + "\n";
        }
        if (dice.chance(kPrecisionPercent)) {
            static const std::vector<std::string> kPrecisions = {"fx8", "fx12", "float", "ideal"};
            out += "precision " + dice.pick(kPrecisions) + "\n";
        }
    }
    out += "\n[render target]\nsize " + std::to_string(width) + " " + std::to_string(height) + "\n";
    if (full) {
        if (dice.chance(kFloatTargetPercent))
            out += dice.chance(50) ? "format A16B16G16R16F\n" : "format A32B32G32R32F\n";
        else if (dice.chance(kX8TargetPercent))
            out += "format X8R8G8B8\n";
    }
    out += "clear " + hexWord(dice.word()) + "\n";
    if (full && dice.chance(kDepthPercent)) {
        env.depth = true;
        out += "depth on " + (dice.chance(30) ? std::string("1") : number(dice.thousandths(0, 1))) + "\n";
    }
    out += "\n";
    const uint32_t sampled = ps11::sampledStages(program);
    const BumpStages bump = bumpStagesOf(program);
    for (int stage = 0; stage < 8; ++stage)
        if (sampled & (1u << stage)) {
            const bool signedTexels = bump.signedTexels & (1u << stage);
            out +=
                full ? fullTextureSection(dice, stage, signedTexels) : plainTextureSection(dice, stage, signedTexels);
        }
    for (int stage = 0; stage < 8; ++stage) {
        if (!(bump.matrices & (1u << stage))) continue;
        out += "[stage " + std::to_string(stage) + "]\nbumpenvmat";
        for (int k = 0; k < 4; ++k) out += " " + number(dice.thousandths(-1, 1));
        out +=
            "\nlscale " + number(dice.thousandths(0, 2)) + "\nloffset " + number(dice.thousandths(-0.5, 0.5)) + "\n\n";
    }
    if (full) {
        out += renderStateSection(dice, env.depth);
        env.perspective = dice.chance(kPerspectivePercent);
        if (dice.chance(kExtraTrianglesPercent)) env.extraTriangles = dice.range(1, 3);
        if (dice.chance(kWideCoordinatesPercent)) {
            static const std::vector<int> kSpans = {1, 2, 4};
            const int k = dice.pick(kSpans);
            env.coordinateLo = -k, env.coordinateHi = k + 1;
        }
    }
    out += "[constants]\n";
    for (int c = 0; c < ps11::registerCount(RegType::Const, minor); ++c) {
        out += "c" + std::to_string(c);
        for (int k = 0; k < 4; ++k) out += " " + number(dice.thousandths(-1, 1));
        out += "\n";
    }
    out += "\n[pixel shader]\n" + shader + "\n\n[test]\ndraw triangles xyzrhw\n";
    // The quad's corners sit half a pixel outside the target (the 1:1 mapping of `draw quad`),
    // two triangles 0 1 2 and 0 2 3. u and v range over [-0.5, 1.5] (or wider) so wrap, mirror,
    // clamp and border all show.
    const double lo = -0.5, hx = width - 0.5, hy = height - 0.5;
    const std::array<std::array<double, 2>, 4> corners = {{{lo, lo}, {hx, lo}, {hx, hy}, {lo, hy}}};
    std::array<std::string, 4> vertices;
    for (size_t k = 0; k < 4; ++k) vertices[k] = vertexLine(dice, env, minor, corners[k][0], corners[k][1]);
    for (size_t k : {0, 1, 2, 0, 2, 3}) out += vertices[k] + "\n";
    // Triangles over the quad, partly outside the target: their edges cut quads, they overlap
    // each other, and they meet the depth test, blending and the write mask over pixels the
    // quad has just written.
    for (int t = 0; t < env.extraTriangles; ++t)
        for (int k = 0; k < 3; ++k)
            out += vertexLine(dice, env, minor, dice.thousandths(-0.25 * width, 1.25 * width),
                              dice.thousandths(-0.25 * height, 1.25 * height)) +
                   "\n";
    return out;
}

bool parsesAsTestFile(const std::string& text) {
    ps11::TestFile file;
    std::vector<ps11::TestFileError> errors;
    return ps11::parseTestFile(text, "shrink.ps11test", file, errors);
}

// Simpler versions of a case file's environment (never its shader), the boldest first: a whole
// section left out (every one but [require], [render target], [pixel shader] and [test]); an
// extra triangle of the draw left out; one keyword line left out ([require] version and the
// target's size stay); a texture down to its level 0; the vertices at rhw 1, then at z 0. Some
// do not parse (a sampler's filter line is fine to drop, a texture's format line is not): the
// caller checks.
std::vector<std::string> simplerEnvironments(const std::string& text) {
    const std::vector<std::string> lines = splitLines(text);
    struct Section {
        std::string name;   // "texture 0", "render state", ...
        size_t begin, end;  // the section line, one past its last line
    };
    std::vector<Section> sections;
    for (size_t i = 0; i < lines.size(); ++i) {
        if (!lines[i].starts_with("[")) continue;
        if (!sections.empty()) sections.back().end = i;
        const size_t close = lines[i].find(']');
        sections.push_back(
            {lines[i].substr(1, close == std::string::npos ? std::string::npos : close - 1), i, lines.size()});
    }
    std::vector<std::string> out;
    auto without = [&](size_t begin, size_t end) {
        std::vector<std::string> kept(lines.begin(), lines.begin() + long(begin));
        kept.insert(kept.end(), lines.begin() + long(end), lines.end());
        out.push_back(joinLines(kept));
    };
    auto isShaderOrTest = [](const std::string& name) { return name.starts_with("pixel shader") || name == "test"; };
    for (const Section& s : sections)
        if (s.name != "require" && s.name != "render target" && !isShaderOrTest(s.name)) without(s.begin, s.end);
    // The draw's vertex lines: 6 for the quad, then the extra triangles, 3 lines each.
    std::vector<size_t> vertexLines;
    for (const Section& s : sections)
        if (s.name == "test")
            for (size_t i = s.begin + 1; i < s.end; ++i)
                if (!lines[i].empty() && (lines[i][0] == '-' || (lines[i][0] >= '0' && lines[i][0] <= '9')))
                    vertexLines.push_back(i);
    for (size_t v = 6; v + 3 <= vertexLines.size() && vertexLines[v] + 2 == vertexLines[v + 2]; v += 3)
        without(vertexLines[v], vertexLines[v] + 3);
    for (const Section& s : sections) {
        if (isShaderOrTest(s.name) || s.name.starts_with("texture")) continue;
        for (size_t i = s.begin + 1; i < s.end; ++i) {
            const std::vector<std::string> words = wordsOf(lines[i]);
            if (words.empty() || words[0].starts_with("%")) continue;
            if ((s.name == "require" && words[0] == "version") || (s.name == "render target" && words[0] == "size"))
                continue;
            without(i, i + 1);
        }
    }
    // A mip chain down to its level 0: the levels line and the levels after 0 go.
    for (const Section& s : sections) {
        if (!s.name.starts_with("texture")) continue;
        size_t levels = 0, level1 = 0;
        for (size_t i = s.begin + 1; i < s.end; ++i) {
            const std::vector<std::string> words = wordsOf(lines[i]);
            if (words.size() == 2 && words[0] == "levels") levels = i;
            if (words.size() == 2 && words[0] == "level" && words[1] != "0" && !level1) level1 = i;
        }
        if (!levels) continue;
        size_t end = s.end;
        while (end > s.begin && lines[end - 1].empty()) --end;  // the blank line after the section stays
        std::vector<std::string> kept;
        for (size_t i = 0; i < lines.size(); ++i)
            if (i != levels && !(level1 && i >= level1 && i < end)) kept.push_back(lines[i]);
        out.push_back(joinLines(kept));
    }
    // Every vertex at rhw 1 (no perspective), then at z 0.
    for (size_t word : {size_t(3), size_t(2)}) {
        const char* value = word == 3 ? "1" : "0";
        std::vector<std::string> changed = lines;
        bool any = false;
        for (size_t i : vertexLines) {
            std::vector<std::string> words = wordsOf(lines[i]);
            if (words.size() <= word || words[word] == value || words[word] == (word == 3 ? "1.000" : "0.000"))
                continue;
            words[word] = value;
            std::string line;
            for (const std::string& w : words) line += (line.empty() ? "" : " ") + w;
            changed[i] = line;
            any = true;
        }
        if (any) out.push_back(joinLines(changed));
    }
    return out;
}

}  // namespace ps11test
