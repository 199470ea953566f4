// The ps11 command line: one binary, one subcommand per job (asm, disasm, check, test,
// eval, golden, isa, demo, bench, version). Each subcommand parses its own options; user errors print a message that
// names the file and place and exit 1, usage errors exit 2.
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/disassembler.h"
#include "ps11/encoder.h"
#include "ps11/isa_doc.h"
#include "ps11/json_internal.h"
#include "ps11/suggest.h"
#include "ps11/validator.h"
#include "ps11/version.h"
#include "tools/cli_util.h"
#include "tools/cmd_bench.h"
#include "tools/demo_report.h"
#include "tools/cmd_eval.h"
#include "tools/cmd_golden.h"
#include "tools/cmd_hardware.h"
#include "tools/cmd_info.h"
#include "tools/cmd_compare.h"
#include "tools/cmd_debug.h"
#include "tools/cmd_ranges.h"
#include "tools/cmd_glare.h"
#include "tools/cmd_stress.h"
#include "tools/cmd_shade.h"
#include "tools/cmd_test.h"

namespace ps11::cli {
namespace {

const char* kUsageText =
    "usage: ps11 <command> [options]\n"
    "  asm FILE|- [-o OUT.bin] [--hex] [--no-validate] [-D NAME[=VALUE]] [-I DIR]\n"
    "                         assemble ps_1_1 … ps_1_4 text to D3D9 tokens\n"
    "  disasm FILE|- [--hex-input]\n"
    "                         tokens (binary, or hex words with --hex-input) → text\n"
    "  check FILE... [--json] [-D NAME[=VALUE]] [-I DIR]\n"
    "                         validate and print statistics (slots, constants, read ports)\n"
    "  check --ranges FILE... [--hardware H] [--cN x,y,z,w] [--texN-range lo,hi] [--texN-point]\n"
    "        [--vN-range lo,hi] [--tcN-range lo,hi] [--json]\n"
    "                         value ranges per instruction, where clamps act and from which\n"
    "                         input on, and r0's worst-case fx8/fx12 rounding against float\n"
    "  test FILE.ps11test... [--backend emu|gl|both] [--gl osmesa|egl] [--hardware H] [--precision P]\n"
    "       [--no-skip] [-v]\n"
    "                         run .ps11test files (both: cross-check the two renderers)\n"
    "  compare SHADER.psh|FILE.ps11test [--size WxH] [--seed S] [--hardware H] [--precision P]\n"
    "          [--heatmap OUT.png] [--json] [--gl osmesa|egl]\n"
    "  compare --random N [--seed S] [--minor 1..4] [--out DIR] [--json]\n"
    "                         the emulator against the GL renderer, draw by draw\n"
    "  shade SHADER.psh [--texN IMG] [--filterN point|linear] [--cN x,y,z,w] [--size WxH] [--backend emu|gl]\n"
    "        [--hardware H | --precision P] [--no-skip] -o OUT.png\n"
    "                         run one shader over a full-screen quad on images\n"
    "  glare --list | --report [--json|--markdown]\n"
    "  glare --technique T (--scene S | --in IMG|DIR) [-o OUT.png] [--frames N] [--size WxH] [--backend emu|gl]\n"
    "        [--hardware H | --precision P] [--quality Q] [--set name=value] [--dump-passes DIR]\n"
    "        [--graph OUT.dot] [--compare] [--json] [--no-skip]\n"
    "                         the glare techniques on a built-in scene or an image, pass by pass\n"
    "  bench [--technique T|all] [--quality Q|all] [--set name=v1,v2,...] [--hardware H|all]\n"
    "        [--backend emu|gl|both] [--gl-mode native|exact] [--scene S | --in IMG|DIR] [--size WxH] [--frames N] [--json]\n"
    "                         run time against error: a sweep of settings, hardware and renderers, each row\n"
    "                         timed and measured against ideal (and the intended math), with the Pareto front\n"
    "  eval SHADER.psh [v0=r,g,b,a] [t0=u,v,w,q] [c0=x,y,z,w] ... [--hardware H] [--precision P]\n"
    "       [--max-value M] [--texN [FORMAT:]WORD]\n"
    "                         run a shader for one pixel and print r0\n"
    "  debug SHADER.psh [the inputs of eval] [--hardware H] [--json]\n"
    "                         one pixel instruction by instruction, the class beside ideal,\n"
    "                         why they differ and where they first part by more than a level\n"
    "  debug --technique T (--scene S | --in IMG) --pixel X,Y [--frame N] [--size WxH] [--set name=value]...\n"
    "        [--hardware H] [--json]\n"
    "                         one output pixel of a glare frame followed back through its passes: each\n"
    "                         pass traced at the texels that mattered beside ideal, and the pass that\n"
    "                         added the most error\n"
    "  stress [--json] [--size N] [--hardware H]\n"
    "                         numerical stability: each 8-bit pitfall predicted, measured and fixed on the\n"
    "                         1.1-class card, the quality metrics per technique, robustness (NaN, Inf, HDR)\n"
    "  hardware [--json]      the emulated GPUs (hardware classes) and what each one changes\n"
    "  info [--gl osmesa|egl] [--json]\n"
    "                         version, default hardware, executor kernels, the OpenGL context\n"
    "  golden (--check|--regen) [DIR]\n"
    "                         golden disassembly and round trips of the shader corpus\n"
    "  isa                    print the instruction table (markdown, as in docs/isa.md)\n"
    "  demo [--out DIR] [--quick] [--size WxH] [--threads N] [--hardware H]\n"
    "                         the main job: the five glare techniques on the built-in scenes, emulated,\n"
    "                         ideal and on GL, fits ps_1_1, time against error, stability, a debug\n"
    "                         trace: a report in DIR/index.html (default ps11-demo/)\n"
    "  version, --version     print the ps11 version\n"
    "  help, --help           print this text\n";

int usage(const std::string& message) {
    if (!message.empty()) std::cerr << "ps11: " << message << "\n";
    std::cerr << kUsageText;
    return kUsage;
}

// Assembles and (optionally) validates one file; prints diagnostics.
std::optional<Program> assembleText(const std::string& text, const std::string& path, const PreprocessOptions& pp,
                                    bool doValidate, ShaderStats* stats, Diagnostics& diags) {
    AssembleOptions options;
    options.preprocess = pp;
    std::string name = path == "-" ? "<stdin>" : path;
    std::optional<Program> prog = parseAssembly(text, name, options, diags);
    if (prog && doValidate) validate(*prog, diags, stats);
    return prog;
}

std::optional<Program> assembleFile(const std::string& path, const PreprocessOptions& pp, bool doValidate,
                                    ShaderStats* stats, Diagnostics& diags) {
    std::optional<std::string> text = readFile(path);
    if (!text) return std::nullopt;
    return assembleText(*text, path, pp, doValidate, stats, diags);
}

int cmdAsm(const std::vector<std::string>& args) {
    std::string input, output;
    bool hex = false, doValidate = true;
    PreprocessOptions pp;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        std::string err;
        if (a == "--hex") {
            hex = true;
        } else if (a == "--no-validate") {
            doValidate = false;
        } else if (a == "-o") {
            if (i + 1 >= args.size()) return usage("-o needs a file name");
            output = args[++i];
        } else if (takePreprocessorOption(args, i, pp, err)) {
            if (!err.empty()) return usage(err);
        } else if (a.size() > 1 && a[0] == '-') {
            return usage("asm: " + unknownOption(a, {"--hex", "--no-validate", "-o", "-D", "-I"}));
        } else if (input.empty()) {
            input = a;
        } else {
            return usage("asm takes one input file");
        }
    }
    if (input.empty()) return usage("asm needs an input file (or - for standard input)");
    Diagnostics diags;
    std::optional<Program> prog = assembleFile(input, pp, doValidate, nullptr, diags);
    std::cerr << diags.formatAll();
    if (!prog || diags.hasErrors()) return kUserError;
    std::vector<uint32_t> tokens = encode(*prog);
    if (!output.empty()) {
        std::string bytes;
        bytes.reserve(tokens.size() * 4);
        for (uint32_t t : tokens)
            for (int b = 0; b < 4; ++b) bytes += char((t >> (8 * b)) & 0xFF);
        if (!writeFile(output, bytes)) return kUserError;
    }
    if (hex || output.empty()) std::cout << hexWords(tokens);
    return kOk;
}

// What a shader file holds: binary tokens, hex words as text, or assembly text.
enum class InputKind { Binary, HexText, Assembly };

InputKind classify(const std::string& data) {
    for (unsigned char c : data)
        if (c == 0 || (c < 0x20 && c != '\n' && c != '\r' && c != '\t') || c == 0x7f) return InputKind::Binary;
    // Text: hex words when the first word (after comments) is 0x… or 8 hex digits.
    size_t i = 0;
    while (i < data.size()) {
        while (i < data.size() && std::isspace(static_cast<unsigned char>(data[i]))) ++i;
        if (i < data.size() && (data[i] == ';' || data[i] == '#' || data.compare(i, 2, "//") == 0)) {
            while (i < data.size() && data[i] != '\n') ++i;
            continue;
        }
        break;
    }
    if (data.compare(i, 2, "0x") == 0 || data.compare(i, 2, "0X") == 0) return InputKind::HexText;
    size_t n = 0;
    while (i + n < data.size() && std::isxdigit(static_cast<unsigned char>(data[i + n]))) ++n;
    if (n == 8 && (i + n == data.size() || !std::isalnum(static_cast<unsigned char>(data[i + n]))))
        return InputKind::HexText;
    return InputKind::Assembly;
}

// Reads tokens from a file: binary, or hex words (forced with --hex-input, else detected).
std::optional<Program> decodeData(const std::optional<std::string>& data, const std::string& path, bool hexInput,
                                  Diagnostics& diags) {
    if (!data) return std::nullopt;
    uint32_t fileId = diags.addFile(path == "-" ? "<stdin>" : path);
    InputKind kind = hexInput ? InputKind::HexText : classify(*data);
    if (kind == InputKind::Assembly && !data->empty()) {
        SourceLoc at;
        at.fileId = fileId;
        at.line = 1;
        diags.error("P3019", at,
                    "this looks like assembly text, not a token stream; use 'ps11 asm' or 'ps11 check' on it "
                    "(hex words are read with --hex-input)");
        return std::nullopt;
    }
    std::optional<std::vector<uint32_t>> tokens =
        kind == InputKind::HexText ? tokensFromHex(*data, fileId, diags) : tokensFromBinary(*data, fileId, diags);
    if (!tokens) return std::nullopt;
    return decode(*tokens, fileId, diags);
}

std::optional<Program> decodeFile(const std::string& path, bool hexInput, Diagnostics& diags) {
    return decodeData(readFile(path), path, hexInput, diags);
}

int cmdDisasm(const std::vector<std::string>& args) {
    std::string input;
    bool hexInput = false;
    for (const std::string& a : args) {
        if (a == "--hex-input") {
            hexInput = true;
        } else if (a.size() > 1 && a[0] == '-') {
            return usage("disasm: " + unknownOption(a, {"--hex-input"}));
        } else if (input.empty()) {
            input = a;
        } else {
            return usage("disasm takes one input file");
        }
    }
    if (input.empty()) return usage("disasm needs an input file (or - for standard input)");
    Diagnostics diags;
    std::optional<Program> prog = decodeFile(input, hexInput, diags);
    std::cerr << diags.formatAll();
    if (!prog || diags.hasErrors()) return kUserError;
    std::cout << disassemble(*prog);
    return kOk;
}

int cmdCheck(const std::vector<std::string>& args) {
    std::vector<std::string> inputs;
    bool json = false, hexInput = false, ranges = false, rangeOptionGiven = false;
    PreprocessOptions pp;
    RangeOptions rangeOptions;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        std::string err;
        if (a == "--json") {
            json = true;
        } else if (a == "--hex-input") {
            hexInput = true;
        } else if (a == "--ranges") {
            ranges = true;
        } else if (takePreprocessorOption(args, i, pp, err)) {
            if (!err.empty()) return usage(err);
        } else if (takeRangeOption(args, i, rangeOptions, err)) {
            if (!err.empty()) return usage("check: " + err);
            rangeOptionGiven = true;
        } else if (a.size() > 1 && a[0] == '-') {
            return usage("check: " + unknownOption(a, {"--json", "--hex-input", "--ranges", "--hardware", "--c0",
                                                       "--tex0-range", "--tex0-point", "--v0-range", "--tc0-range",
                                                       "-D", "-I"}));
        } else {
            inputs.push_back(a);
        }
    }
    if (inputs.empty()) return usage("check needs at least one shader file");
    if (rangeOptionGiven && !ranges) return usage("check: --hardware, --cN and the range options need --ranges");
    int status = kOk;
    // --json: one object per file; --ranges --json: the range proof's object per file.
    nlohmann::ordered_json jsonOut = nlohmann::ordered_json::array();
    for (size_t n = 0; n < inputs.size(); ++n) {
        const std::string& path = inputs[n];
        Diagnostics diags;
        ShaderStats stats;
        std::optional<Program> prog;
        // Token streams (binary or hex words) are decoded, text is assembled.
        std::optional<std::string> data = readFile(path);
        if (!data) {
            status = kUserError;
            continue;
        }
        if (hexInput || classify(*data) != InputKind::Assembly) {
            prog = decodeData(data, path, hexInput, diags);
            if (prog) validate(*prog, diags, &stats);
        } else {
            prog = assembleText(*data, path, pp, true, &stats, diags);
        }
        std::cout.flush();
        std::cerr << diags.formatAll();
        bool ok = prog && !diags.hasErrors();
        if (!ok) status = kUserError;
        if (ranges) {
            nlohmann::ordered_json one;
            if (ok && checkRanges(*prog, path, rangeOptions, json, &one)) {
                if (json) jsonOut.push_back(std::move(one));
            } else {
                status = kUserError;
            }
            continue;
        }
        if (json) {
            nlohmann::ordered_json one;
            one["file"] = path;
            one["valid"] = ok;
            one["errors"] = diags.errorCount();
            // statsToJson is ps11core's text (the library keeps nlohmann out of its headers): read back.
            if (prog) one["stats"] = nlohmann::ordered_json::parse(statsToJson(stats));
            jsonOut.push_back(std::move(one));
        } else {
            std::cout << path << ": " << (ok ? "valid" : "INVALID") << "\n";
            if (prog) std::cout << statsToText(stats) << "\n";
        }
    }
    // One object per file, each on its own line.
    if (json && !ranges) std::cout << json::dump(jsonOut, 1) << "\n";
    // One shader: its object (docs/intervals.md "The range proof"); several: an array of them.
    if (json && ranges)
        std::cout << (jsonOut.size() == 1 ? jsonOut[0] : jsonOut)
                         .dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace)
                  << "\n";
    return status;
}

// The main job (README): the report of tools/demo_report.h.
int cmdDemo(const std::vector<std::string>& args) {
    DemoReportOptions demo;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--quick") {
            demo.quick = true;
        } else if (a == "--size" || a == "--threads" || a == "--out" || a == "--hardware") {
            if (i + 1 >= args.size()) return usage("demo: " + a + " needs a value");
            const std::string& v = args[++i];
            if (a == "--hardware") {
                demo.hardware = findHardware(v);
                if (!demo.hardware) return usage("demo: " + unknownHardwareMessage(v));
            } else if (a == "--size") {
                if (!parseSize(v, demo.width, demo.height, kMaxSizeSide, kMinGlareFrameSide))
                    return usage("demo: --size takes " + sizeRule(kMaxSizeSide, kMinGlareFrameSide) + ", not " + quote(v));
            } else if (a == "--out") {
                demo.outDir = v;
            } else if (!parseCount(v, 0, 256, demo.threads)) {
                return usage("demo: --threads takes a number 0..256, not " + quote(v));
            }
        } else {
            return usage("demo: unknown argument " + quote(a) +
                         didYouMean(a, {"--quick", "--out", "--size", "--threads", "--hardware"}));
        }
    }
    return writeDemoReport(demo);
}

}  // namespace
}  // namespace ps11::cli

int main(int argc, char** argv) {
    using namespace ps11::cli;
    if (argc < 2) return usage("");
    std::string cmd = argv[1];
    std::vector<std::string> args(argv + 2, argv + argc);
    // The commands, in one table: dispatch and the "did you mean" of an unknown command.
    struct Command {
        std::string_view name;
        int (*run)(const std::vector<std::string>&);
    };
    static const Command kCommands[] = {
        {"asm", cmdAsm},
        {"disasm", cmdDisasm},
        {"check", cmdCheck},
        {"test", ps11::cmdTest},
        {"compare", ps11::cmdCompare},
        {"glare", ps11::cmdGlare},
        {"bench", ps11::cmdBench},
        {"stress", ps11::cmdStress},
        {"shade", ps11::cmdShade},
        {"eval", ps11::cmdEval},
        {"debug", ps11::cmdDebug},
        {"golden", cmdGolden},
        {"demo", cmdDemo},
        {"hardware", ps11::cmdHardware},
        {"info", ps11::cmdInfo},
        {"isa",
         [](const std::vector<std::string>&) {
             std::cout << ps11::isaMarkdownTable();
             return int(kOk);
         }},
        {"version",
         [](const std::vector<std::string>&) {
             std::cout << "ps11 " << ps11::versionString() << "\n";
             return int(kOk);
         }},
        {"help",
         [](const std::vector<std::string>&) {
             std::cout << kUsageText;
             return int(kOk);
         }},
    };
    if (cmd == "--version") cmd = "version";
    if (cmd == "-h" || cmd == "--help") cmd = "help";
    std::vector<std::string_view> names;
    for (const Command& c : kCommands) {
        if (c.name == cmd) return c.run(args);
        names.push_back(c.name);
    }
    return usage("unknown command " + ps11::quote(cmd) + ps11::didYouMean(cmd, names));
}
