// `ps11 eval` (stage: command line over the assembler, the validator and the executor): one
// pixel of a shader with v#, t# and c# given as NAME=x,y,z,w and stages bound to 1×1 A8R8G8B8
// textures (--texN 0xAARRGGBB); prints r0 as floats (and grid integers in fx profiles), and
// whether texkill discarded the pixel or the shader replaced depth.
#include "tools/cmd_eval.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/decoded_program.h"
#include "ps11/diagnostics.h"
#include "ps11/executor.h"
#include "ps11/testfile.h"
#include "ps11/testfile_textures.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"
#include "ps11/validator.h"
#include "tools/cli_util.h"
#include "runner/test_eval.h"

namespace ps11 {
namespace {

constexpr const char* kUsage =
    "usage: ps11 eval SHADER.psh [v0=r,g,b,a] [v1=...] [t0=u,v,w,q] ... [t7=...] [c0=x,y,z,w] ... [c7=...]\n"
    "                 [--hardware H] [--precision fx8|fx12|float|ideal] [--max-value M]\n"
    "                 [--tex0 [FORMAT:]WORD] ... [--tex7 ...]\n"
    "  values take 1-4 comma-separated floats (missing components are 0); v0/v1 also take 0xAARRGGBB;\n"
    "  --texN binds a 1x1 texture to stage N: a word in the format's packing (default A8R8G8B8\n"
    "  0xAARRGGBB; e.g. V8U8:0x807f); unbound stages sample (0, 0, 0, 1);\n"
    "  --hardware picks the emulated GPU (`ps11 hardware` lists them; default: the 1.1-class card,\n"
    "  or the 1.4-class card for ps_1_4); --precision and --max-value override its values\n";

// The command whose arguments are parsed ("eval" or "debug") and its usage text.
const char* g_command = "eval";
const char* g_usage = kUsage;

int usageError(const std::string& message) {
    std::cerr << "ps11: " << g_command << ": " << message << "\n" << g_usage;
    return cli::kUsage;
}

int userError(const std::string& message) {
    std::cerr << "ps11: " << g_command << ": " << message << "\n";
    return cli::kUserError;
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

// Parses NAME=VALUE; returns an exit code (kOk = consumed).
int takeRegister(const std::string& arg, EvalArgs& out) {
    size_t eq = arg.find('=');
    std::string name = lower(arg.substr(0, eq));
    std::string value = arg.substr(eq + 1);
    std::optional<Vec4>* slot = nullptr;
    if (name.size() == 2 && name[1] >= '0' && name[1] <= '7') {
        int n = name[1] - '0';
        if (name[0] == 'v' && n < 2) slot = &out.color[n];
        if (name[0] == 't') slot = &out.texcoord[n];
        if (name[0] == 'c') slot = &out.constant[n];
    }
    if (!slot) return usageError("unknown input " + quote(arg.substr(0, eq)) + " (expected v0, v1, t0..t7 or c0..c7)");
    if (*slot) return userError(name + " given twice");
    std::optional<Vec4> v = cli::parseVector(value, name[0] == 'v');
    if (!v) return userError("bad value for " + name + ": " + quote(value));
    *slot = v;
    return cli::kOk;
}

}  // namespace

int parseEvalArgs(const std::vector<std::string>& args, const char* command, const char* usage, EvalArgs& ea) {
    g_command = command;
    g_usage = usage;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "-h" || a == "--help") {
            std::cout << usage;
            return kHelpShown;
        }
        bool isTex = a.size() == 6 && a.compare(0, 5, "--tex") == 0 && a[5] >= '0' && a[5] <= '7';
        if (a == "--precision" || a == "--max-value" || a == "--hardware" || isTex) {
            if (i + 1 >= args.size()) return usageError(a + " needs a value");
            const std::string& v = args[++i];
            if (a == "--hardware") {
                ea.hardware = findHardware(v);
                if (!ea.hardware)
                    return usageError(unknownHardwareMessage(v));
            } else if (a == "--precision") {
                std::optional<Precision> p = parsePrecision(v);
                if (!p) return usageError("unknown precision " + quote(v) + " (expected fx8, fx12, float or ideal)");
                ea.precision = *p;
            } else if (a == "--max-value") {
                std::optional<float> m = cli::parseFloat(v);
                if (!m || *m <= 0)
                    return userError("bad value for --max-value: " + quote(v) + " (expected a float > 0)");
                ea.maxValue = *m;
            } else {
                const int stage = a[5] - '0';
                std::string word = v;
                if (size_t colon = v.find(':'); colon != std::string::npos) {
                    std::optional<TexFormat> f = parseTexFormat(v.substr(0, colon));
                    if (!f || isFloatFormat(*f))
                        return userError("bad format in " + a + ": " + quote(v.substr(0, colon)) +
                                         " (expected a packed format: A8R8G8B8, X8R8G8B8, A8, L8, A8L8, V8U8, "
                                         "L6V5U5, X8L8V8U8, Q8W8V8U8 or V16U16)");
                    ea.textureFormat[size_t(stage)] = *f;
                    word = v.substr(colon + 1);
                }
                std::optional<uint32_t> w = cli::parseHexWord(word);
                const int bits = formatBits(ea.textureFormat[size_t(stage)]);
                if (!w || (bits < 32 && (*w >> bits) != 0))
                    return userError("bad value for " + a + ": " + quote(v) + " (expected a hex word of " +
                                     std::to_string(bits) + " bits, e.g. 0xff808080)");
                ea.texture[size_t(stage)] = *w;
            }
        } else if (a.size() > 1 && a[0] == '-') {
            return usageError(cli::unknownOption(a, {"--hardware", "--precision", "--max-value", "--tex0", "--tex1", "--tex2",
                                                     "--tex3", "--tex4", "--tex5", "--tex6", "--tex7", "--help"}));
        } else if (a.find('=') != std::string::npos) {
            if (int rc = takeRegister(a, ea); rc != cli::kOk) return rc;
        } else if (ea.shader.empty()) {
            ea.shader = a;
        } else {
            return usageError("eval takes one shader file (" + quote(a) + " is a second one)");
        }
    }
    if (ea.shader.empty()) return usageError(std::string(command) + " needs a shader file");
    return cli::kOk;
}

int loadEvalProgram(const EvalArgs& ea, std::optional<Program>& program, HardwareConfig& hw) {
    std::optional<std::string> text = cli::readFile(ea.shader);
    if (!text) return cli::kUserError;
    Diagnostics diags;
    std::string name = ea.shader == "-" ? "<stdin>" : ea.shader;
    program = parseAssembly(*text, name, AssembleOptions{}, diags);
    if (program) validate(*program, diags);
    std::cerr << diags.formatAll();
    if (!program || diags.hasErrors()) return cli::kUserError;

    hw = resolveHardware(ea.hardware, program->version.minor, ea.precision, ea.maxValue);
    if (program->version.minor > hw.hardware->maxMinor)
        return userError("hardware " + std::string(hw.hardware->name) + " runs ps_1_1 ... ps_1_" +
                         std::to_string(hw.hardware->maxMinor) + "; " + name + " is ps_1_" +
                         std::to_string(program->version.minor));
    return cli::kOk;
}

std::unique_ptr<Executor> makeEvalExecutor(const Program& program, const HardwareConfig& hw, const EvalArgs& ea) {
    Diagnostics diags;
    std::unique_ptr<Executor> executor = Executor::create(program, executorOptionsFor(hw), diags);
    std::cerr << diags.formatAll();
    if (!executor) return nullptr;
    for (int c = 0; c < exec::kNumConsts; ++c)
        if (ea.constant[c]) executor->setConstant(c, *ea.constant[c]);
    return executor;
}

int bindEvalTextures(const EvalArgs& ea, const HardwareConfig& hw, uint32_t sampled, TextureSampler& sampler) {
    sampler.setWeightBits(hw.weightBits);
    for (int stage = 0; stage < kMaxTextureStages; ++stage) {
        if (!ea.texture[stage]) continue;
        TextureDesc desc;
        desc.stage = stage;
        desc.format.value = ea.textureFormat[size_t(stage)];
        desc.width = desc.height = 1;
        TextureLevel level;
        level.width = level.height = 1;
        level.hasFill = true;
        level.fill.bits = *ea.texture[stage];
        desc.data.push_back(level);
        std::string why;
        std::optional<Texture> texture = textureFromDesc(desc, hw.hardware->signedDecode, why);
        if (!texture) return userError("cannot build the texture of --tex" + std::to_string(stage) + ": " + why);
        sampler.bind(stage, std::make_shared<const Texture>(std::move(*texture)));
    }
    for (int stage = 0; stage < kMaxTextureStages; ++stage)
        if ((sampled & (1u << stage)) && !ea.texture[stage])
            std::cerr << "ps11: " << g_command << ": note: the shader samples stage " << stage << ", which has no --tex"
                      << stage << "; D3D returns (0, 0, 0, 1) there\n";
    return cli::kOk;
}

ps11test::EvalInputs EvalArgs::inputs() const {
    ps11test::EvalInputs in;
    for (int r = 0; r < 2; ++r)
        if (color[size_t(r)]) in.color[size_t(r)] = &*color[size_t(r)];
    for (int r = 0; r < 8; ++r)
        if (texcoord[size_t(r)]) in.texture[size_t(r)] = &*texcoord[size_t(r)];
    return in;
}

int cmdEval(const std::vector<std::string>& args) {
    EvalArgs ea;
    if (int rc = parseEvalArgs(args, "eval", kUsage, ea); rc != cli::kOk) return rc == kHelpShown ? cli::kOk : rc;
    std::optional<Program> program;
    HardwareConfig hw;
    if (int rc = loadEvalProgram(ea, program, hw); rc != cli::kOk) return rc;
    std::unique_ptr<Executor> executor = makeEvalExecutor(*program, hw, ea);
    if (!executor) return cli::kUserError;
    TextureSampler sampler;
    if (int rc = bindEvalTextures(ea, hw, executor->sampledStages(), sampler); rc != cli::kOk) return rc;
    ps11test::EvalOutcome out = ps11test::evalOnePixel(*executor, sampler, ea.inputs());

    const Precision p = hw.precision;
    std::cout << "ps_" << program->version.major << "_" << program->version.minor << ", hardware " << hw.describe()
              << "\n";
    std::cout << "r0     ";
    for (int c = 0; c < 4; ++c) std::cout << (c ? " " : "") << num(out.color[c]);
    std::cout << "\n";
    if (isFixedPoint(p)) {
        std::cout << "grid   ";
        for (int c = 0; c < 4; ++c) std::cout << (c ? " " : "") << out.grid[c];
        std::cout << "   (value = n/" << gridScale(p) << ")\n";
    }
    if (out.killed) std::cout << "killed (texkill discarded the pixel)\n";
    if (out.hasDepth) std::cout << "depth  " << num(out.depth) << "\n";
    return cli::kOk;
}

}  // namespace ps11
