// `ps11 test` (stage: command line over the .ps11test reader, the assembler, the validator
// and the executor). Each file is parsed, its [pixel shader] is assembled and validated (or must
// fail with the expected diagnostic), its evals and eval probes run on the executor
// (runner/test_eval.cpp), and its draws and pixel probes run on the emu device
// (runner/test_draw.cpp). Commands asked of the gl backend are counted as "not yet runnable".
#include "tools/cmd_test.h"

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/disassembler.h"
#include "ps11/encoder.h"
#include "ps11/diagnostics.h"
#include "ps11/testfile.h"
#include "ps11/validator.h"
#include "tools/cli_util.h"
#include "runner/test_eval.h"

namespace ps11 {
namespace {

constexpr const char* kUsage =
    "usage: ps11 test FILE.ps11test|FOLDER... [--backend emu|gl|both] [--gl osmesa|egl] [--gl-mode exact|native]\n"
    "                 [--hardware H] [--precision fx8|fx12|float|ideal] [--no-skip] [--stats] [-v]\n"
    "  --backend B    emu (the software renderer), gl (the OpenGL renderer) or both: every draw and eval\n"
    "                 on both renderers, their results compared (disagreements fail the file)\n"
    "  --gl KIND      the OpenGL context: osmesa or egl (default: the first that works)\n"
    "  --gl-mode M    exact (default: bit for bit with the emulator, checked) or native (GL's own\n"
    "                 interpolation, filtering, float arithmetic and blending: run and measured against\n"
    "                 the emulator, its probes and differences counted, not failed)\n"
    "  --hardware H   the emulated GPU for every file, overriding [require] hardware (`ps11 hardware` lists\n"
    "                 them); `all` runs the files once per class\n"
    "  --no-skip      the emulator draws every tile (no tile skipping; for comparison: the images are\n"
    "                 the same); with --backend gl or both it applies to the emu side only\n"
    "  --stats        executor statistics and draw statistics per file (with the tiles shaded, filled,\n"
    "                 copied and skipped)\n";

int usageError(const std::string& message) {
    std::cerr << "ps11 test: " << message << "\n" << kUsage;
    return cli::kUsage;
}

struct RunOptions {
    uint8_t backends = kBackendEmu;
    const HardwareClass* hardware = nullptr;  // overrides [require] hardware when given
    std::optional<Precision> precision;       // overrides [require] precision when given
    bool verbose = false;
    bool stats = false;  // print executor statistics per file
    ps11test::RendererFactory glRenderer;  // --backend gl|both
    bool glNative = false;       // --gl-mode native
    bool skipTiles = true;       // --no-skip: false
};

enum class Outcome { Passed, Failed, NotRunnable };

struct FileResult {
    Outcome outcome = Outcome::Passed;
    ps11test::CommandTally tally;   // evals run, probes, commands not runnable yet
    bool skipped = false;  // [require] backend excludes every backend of this run
    bool skippedHardware = false;  // --hardware names a class that cannot run the file's shader
};

std::string where(const std::string& path, uint32_t line) { return line ? path + ":" + std::to_string(line) : path; }

// True if d is the expected failure of the block (code, and place when given).
bool matchesExpectation(const Diagnostics& diags, const Diagnostic& d, const PixelShaderBlock& ps,
                        const std::string& path) {
    if (d.severity != Severity::Error || d.code != ps.failCode) return false;
    if (ps.failLine == 0) return true;
    if (d.loc.tokenIndex >= 0 || diags.fileName(d.loc.fileId) != path) return false;
    return d.loc.line == ps.failLine && (ps.failCol == 0 || d.loc.col == ps.failCol);
}

// Assembles and validates the [pixel shader] block; returns false (after reporting) when the
// result is not what the block expects. A valid program is left in `valid`.
bool checkShader(const TestFile& file, const std::string& path, const RunOptions& opts,
                 std::optional<Program>& valid, Diagnostics& diags) {
    const PixelShaderBlock& ps = file.pixelShader;
    AssembleOptions options;
    // The block is assembled as if it stood alone in the .ps11test file, so every diagnostic
    // carries the file's own line numbers.
    std::optional<Program> program = parseAssembly(ps.textWithFileLines(), path, options, diags);
    if (program) validate(*program, diags);

    if (!ps.expectFail) {
        if (!diags.hasErrors()) {
            if (opts.verbose && !diags.all().empty()) std::cout << diags.formatAll();
            // The toolchain's round-trip property on every valid shader of the corpus:
            // tokens → disassembly → tokens gives the same words.
            std::vector<uint32_t> tokens = encode(*program);
            Diagnostics rt;
            std::optional<Program> decoded = decode(tokens, rt.addFile(path), rt);
            std::optional<Program> again =
                decoded ? parseAssembly(disassemble(*decoded), path + " (disassembly)", options, rt) : std::nullopt;
            if (!again || encode(*again) != tokens) {
                std::cout << where(path, ps.line) << ": [pixel shader] does not round-trip through the disassembler\n"
                          << rt.formatAll();
                return false;
            }
            valid = std::move(program);
            return true;
        }
        std::cout << where(path, ps.line) << ": [pixel shader] does not assemble and validate:\n" << diags.formatAll();
        return false;
    }
    std::string expected = ps.failCode;
    if (ps.failLine) {
        expected += " at " + std::to_string(ps.failLine);
        if (ps.failCol) expected += ":" + std::to_string(ps.failCol);
    }
    if (!diags.hasErrors()) {
        std::cout << where(path, ps.line) << ": expected the shader to fail with " << expected
                  << ", but it assembled and validated\n";
        return false;
    }
    for (const Diagnostic& d : diags.all())
        if (matchesExpectation(diags, d, ps, path)) {
            if (opts.verbose) std::cout << diags.formatAll();
            return true;
        }
    std::cout << where(path, ps.line) << ": expected " << expected << ", got:\n" << diags.formatAll();
    return false;
}

FileResult runFile(const std::string& path, const RunOptions& opts) {
    FileResult result;
    std::optional<std::string> text = cli::readFile(path);
    if (!text) {
        result.outcome = Outcome::Failed;
        return result;
    }
    TestFile file;
    std::vector<TestFileError> errors;
    if (!parseTestFile(*text, path, file, errors)) {
        for (const TestFileError& e : errors) std::cout << formatTestFileError(path, e) << "\n";
        result.outcome = Outcome::Failed;
        return result;
    }
    bool ok = true;
    std::optional<Program> program;
    Diagnostics shaderDiags;
    if (file.pixelShader.present()) ok = checkShader(file, path, opts, program, shaderDiags);
    if (!ok) {
        result.outcome = Outcome::Failed;
        return result;
    }
    uint8_t backends = opts.backends & file.require.backends.value;
    // The class: --hardware, else [require] hardware, else the default of the shader's version;
    // --precision, else [require] precision, and [require] max_value override the class's.
    const RequireDesc& req = file.require;
    const int minor = program ? program->version.minor : req.versionMinor.value;
    const HardwareClass* named = opts.hardware ? opts.hardware : req.hardware.value;
    std::optional<Precision> precisionOverride = opts.precision;
    if (!precisionOverride && req.precision.isSet()) precisionOverride = req.precision.value;
    const HardwareConfig hw = resolveHardware(named, minor, precisionOverride, req.maxValue.value);
    if (minor > hw.hardware->maxMinor) {
        if (opts.hardware) {
            if (opts.verbose)
                std::cout << path << ": skipped: hardware " << hw.hardware->name << " runs ps_1_1 ... ps_1_"
                          << hw.hardware->maxMinor << ", the file needs ps_1_" << minor << "\n";
            result.skippedHardware = true;
            return result;
        }
        std::cout << where(path, req.hardware.line) << ": hardware " << hw.hardware->name << " runs ps_1_1 ... ps_1_"
                  << hw.hardware->maxMinor << ", but the file needs ps_1_" << minor << "\n";
        result.outcome = Outcome::Failed;
        return result;
    }
    if (backends == 0) {
        result.skipped = !file.commands.empty();
        return result;
    }
    ps11test::CommandRunOptions run;
    run.backends = backends;
    run.hardware = hw;
    run.verbose = opts.verbose;
    run.shaderDiags = &shaderDiags;
    run.glRenderer = opts.glRenderer;
    run.glNative = opts.glNative;
    run.skipTiles = opts.skipTiles;
    ps11test::CommandTally& t = result.tally;
    ps11test::runCommands(file, path, program ? &*program : nullptr, run, t);
    if (opts.stats && t.evals) {
        const ExecutorStats& s = t.stats;
        std::cout << path << ": stats (" << hw.describe() << "): " << t.evals << " evals, " << s.pixels
                  << " pixels, " << s.instructions << " instructions executed";
        if (s.pixels) std::cout << " (" << double(s.instructions) / double(s.pixels) << " per pixel)";
        std::cout << ", " << t.texelsFetched << " texels fetched\n";
    }
    if (opts.stats && t.draws.draws) {
        const ps11test::DrawTally& d = t.draws;
        std::cout << path << ": draw stats (" << hw.describe() << "): " << d.draws << " draws, "
                  << d.pixelsShaded << " pixels shaded, " << d.pixelsWritten << " written, " << d.instructions
                  << " instructions executed, " << d.texelsFetched << " texels fetched, " << d.milliseconds
                  << " ms, tiles shaded/filled/copied/skipped " << d.tilesShaded << "/" << d.tilesFilled << "/"
                  << d.tilesCopied << "/" << d.tilesSkipped << "\n";
    }
    if (t.error || t.probesFailed || t.disagreements)
        result.outcome = Outcome::Failed;
    else if (t.pendingGl)
        result.outcome = Outcome::NotRunnable;
    return result;
}

// Runs every file once with `opts` and prints the summary line (prefixed with the class when
// --hardware all runs the files once per class). Returns the exit code.
int runFiles(const std::vector<std::string>& files, const RunOptions& opts, bool perClass);

}  // namespace

int cmdTest(const std::vector<std::string>& args) {
    RunOptions opts;
    bool allHardware = false;
    std::string glKind;
    bool glModeGiven = false;
    std::vector<std::string> files;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--backend" || a == "--precision" || a == "--hardware" || a == "--gl" || a == "--gl-mode") {
            if (i + 1 >= args.size()) return usageError(a + " needs a value");
            const std::string& v = args[++i];
            if (a == "--gl-mode") {
                if (v != "exact" && v != "native")
                    return usageError("unknown GL mode " + quote(v) + " (expected exact or native)");
                opts.glNative = v == "native";
                glModeGiven = true;
            } else if (a == "--gl") {
                if (v != "osmesa" && v != "egl") return usageError("unknown GL context " + quote(v) + " (expected osmesa or egl)");
                glKind = v;
            } else if (a == "--hardware") {
                allHardware = v == "all";
                opts.hardware = allHardware ? nullptr : findHardware(v);
                if (!opts.hardware && !allHardware) return usageError(unknownHardwareMessage(v));
            } else if (a == "--backend") {
                if (v == "emu")
                    opts.backends = kBackendEmu;
                else if (v == "gl")
                    opts.backends = kBackendGl;
                else if (v == "both")
                    opts.backends = kBackendEmu | kBackendGl;
                else
                    return usageError("unknown backend " + quote(v) + " (expected emu, gl or both)");
            } else {
                if (v == "fx8")
                    opts.precision = Precision::Fx8;
                else if (v == "fx12")
                    opts.precision = Precision::Fx12;
                else if (v == "float")
                    opts.precision = Precision::Float;
                else if (v == "ideal")
                    opts.precision = Precision::Ideal;
                else
                    return usageError("unknown precision " + quote(v) + " (expected fx8, fx12, float or ideal)");
            }
        } else if (a == "--stats") {
            opts.stats = true;
        } else if (a == "--no-skip") {
            opts.skipTiles = false;
        } else if (a == "-v" || a == "--verbose") {
            opts.verbose = true;
        } else if (a == "-h" || a == "--help") {
            std::cout << kUsage;
            return cli::kOk;
        } else if (a.size() > 1 && a[0] == '-') {
            return usageError(cli::unknownOption(a, {"--backend", "--gl", "--gl-mode", "--hardware", "--precision",
                                                     "--no-skip", "--stats", "--verbose", "--help"}));
        } else {
            std::error_code ec;
            if (std::filesystem::is_directory(a, ec)) {
                // A folder stands for every .ps11test below it, sorted.
                std::vector<std::string> found = cli::listFiles(a, ".ps11test");
                if (found.empty()) {
                    std::cerr << "ps11 test: no .ps11test files under " << a << "\n";
                    return cli::kUserError;
                }
                files.insert(files.end(), found.begin(), found.end());
            } else {
                files.push_back(a);
            }
        }
    }
    if (files.empty()) return usageError("no .ps11test files given");
    if (glModeGiven && !(opts.backends & kBackendGl)) return usageError("--gl-mode needs --backend gl or both");
    if (opts.backends & kBackendGl) {
        std::string error;
        opts.glRenderer = ps11test::glRendererFactory(glKind, error, opts.glNative);
        if (!opts.glRenderer) {
            std::cerr << "ps11 test: --backend " << (opts.backends & kBackendEmu ? "both" : "gl") << ": " << error << "\n";
            return cli::kUserError;
        }
    }
    if (!allHardware) return runFiles(files, opts, false);
    int rc = cli::kOk;
    for (const HardwareClass& h : hardwareClasses()) {
        opts.hardware = &h;
        if (runFiles(files, opts, true) != cli::kOk) rc = cli::kUserError;
    }
    return rc;
}

namespace {

int runFiles(const std::vector<std::string>& files, const RunOptions& opts, bool perClass) {
    size_t passed = 0, failed = 0, notRunnable = 0, skipped = 0, skippedHardware = 0;
    ps11test::CommandTally total;
    for (const std::string& path : files) {
        FileResult r = runFile(path, opts);
        const ps11test::CommandTally& t = r.tally;
        total.evals += t.evals;
        total.probesPassed += t.probesPassed;
        total.probesFailed += t.probesFailed;
        total.probesTodo += t.probesTodo;
        total.pendingGl += t.pendingGl;
        total.comparedDraws += t.comparedDraws;
        total.comparedPixels += t.comparedPixels;
        total.exactPixels += t.exactPixels;
        total.overOnePixels += t.overOnePixels;
        total.maxDiff = std::max(total.maxDiff, t.maxDiff);
        total.disagreements += t.disagreements;
        total.nativeProbesDiffering += t.nativeProbesDiffering;
        total.nativeDrawsPastTarget += t.nativeDrawsPastTarget;
        if (r.skipped) ++skipped;
        if (r.skippedHardware) {
            ++skippedHardware;
            continue;
        }
        switch (r.outcome) {
            case Outcome::Passed:
                ++passed;
                break;
            case Outcome::Failed:
                ++failed;
                break;
            case Outcome::NotRunnable:
                ++notRunnable;
                break;
        }
        if (opts.verbose) {
            const char* label = r.outcome == Outcome::Failed   ? "FAIL"
                                : r.outcome == Outcome::Passed ? (r.skipped ? "PASS (commands skipped)" : "PASS")
                                                               : "NOT YET RUNNABLE";
            std::cout << label << " " << path;
            if (t.evals) std::cout << " (" << t.evals << (t.evals == 1 ? " eval" : " evals") << ")";
            if (t.draws.draws) std::cout << " (" << t.draws.draws << (t.draws.draws == 1 ? " draw" : " draws") << ")";
            if (t.pendingGl) std::cout << " (gl: " << t.pendingGl << " commands not runnable yet)";
            std::cout << "\n";
        }
    }
    auto plural = [](size_t n, const char* one, const char* many) {
        return std::to_string(n) + " " + (n == 1 ? one : many);
    };
    if (perClass) std::cout << opts.hardware->name << ": ";
    std::cout << plural(files.size(), "file", "files") << ": " << passed << " passed, " << failed << " failed, "
              << notRunnable << " not yet runnable";
    if (total.pendingGl) std::cout << " (not runnable on gl: " << plural(total.pendingGl, "command", "commands") << ")";
    std::cout << "; probes: " << total.probesPassed << " passed, " << total.probesFailed << " failed, "
              << total.probesTodo << " todo";
    if (skipped) std::cout << "; " << skipped << " with commands skipped by [require] backend";
    if (skippedHardware)
        std::cout << "; " << skippedHardware << " skipped: their shader version is beyond hardware "
                  << opts.hardware->name;
    std::cout << "\n";
    if (total.comparedDraws) {
        std::cout << (perClass ? std::string(opts.hardware->name) + ": " : std::string()) << "cross-check ("
                  << ps11test::glRendererDescription() << "): " << plural(total.comparedDraws, "draw", "draws") << ", "
                  << total.comparedPixels << " pixels, " << total.exactPixels << " exact ("
                  << (total.comparedPixels ? 100.0 * double(total.exactPixels) / double(total.comparedPixels) : 100.0)
                  << " %), " << total.overOnePixels << " past the target, max |d| " << total.maxDiff << "; "
                  << plural(total.disagreements, "disagreement", "disagreements") << "\n";
    }
    if (opts.glNative && (opts.backends & kBackendGl))
        std::cout << (perClass ? std::string(opts.hardware->name) + ": " : std::string())
                  << "gl native mode, measured against the emulated card: "
                  << plural(total.nativeProbesDiffering, "probe differs", "probes differ") << " from the expected value, "
                  << plural(total.nativeDrawsPastTarget, "draw or eval", "draws and evals")
                  << " past one level of the emulator's result\n";
    return failed ? cli::kUserError : cli::kOk;
}

}  // namespace

}  // namespace ps11
