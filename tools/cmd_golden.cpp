// `ps11 golden --check|--regen [DIR]`: for every corpus shader (tests/shaders/corpus/**.psh)
// assemble, validate, decode and disassemble; compare the canonical text and tokens with
// DIR/disasm/<path>.txt, and check that the disassembly assembles back to the same tokens.
#include "tools/cmd_golden.h"

#include <filesystem>
#include <iostream>
#include <set>

#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/disassembler.h"
#include "ps11/encoder.h"
#include "ps11/validator.h"
#include "tools/cli_util.h"

namespace ps11::cli {
namespace {

// The golden text: the canonical disassembly, then the tokens as comments, so a golden
// file is itself a valid shader that assembles to the same tokens.
std::optional<std::string> goldenText(const std::string& path, const std::string& rel, std::string& problem) {
    std::optional<std::string> text = readFile(path);
    if (!text) {
        problem = "unreadable";
        return std::nullopt;
    }
    Diagnostics diags;
    AssembleOptions options;
    std::optional<Program> prog = parseAssembly(*text, path, options, diags);
    if (prog) validate(*prog, diags);
    if (!prog || diags.hasErrors()) {
        problem = "does not assemble and validate:\n" + diags.formatAll();
        return std::nullopt;
    }
    std::vector<uint32_t> tokens = encode(*prog);
    Diagnostics d2;
    std::optional<Program> decoded = decode(tokens, d2.addFile(rel), d2);
    if (!decoded) {
        problem = "its tokens do not decode:\n" + d2.formatAll();
        return std::nullopt;
    }
    std::string disasm = disassemble(*decoded);
    Diagnostics d3;
    std::optional<Program> again = parseAssembly(disasm, rel + " (disassembly)", options, d3);
    if (!again) {
        problem = "its disassembly does not assemble:\n" + d3.formatAll() + disasm;
        return std::nullopt;
    }
    std::vector<uint32_t> tokens2 = encode(*again);
    if (tokens2 != tokens) {
        problem = "round trip changed the tokens:\n  first:  " + hexWords(tokens, 1000) + "  second: " +
                  hexWords(tokens2, 1000);
        return std::nullopt;
    }
    std::string out = disasm;
    out += "// tokens (" + std::to_string(tokens.size()) + " words)\n";
    std::string hex = hexWords(tokens, 8);
    size_t start = 0;
    while (start < hex.size()) {
        size_t end = hex.find('\n', start);
        out += "// " + hex.substr(start, end - start) + "\n";
        start = end + 1;
    }
    return out;
}

}  // namespace

int cmdGolden(const std::vector<std::string>& args) {
    bool regen = false, check = false;
    std::string dir;
    for (const std::string& a : args) {
        if (a == "--regen") {
            regen = true;
        } else if (a == "--check") {
            check = true;
        } else if (a.size() > 1 && a[0] == '-') {
            std::cerr << "ps11: golden: " << unknownOption(a, {"--check", "--regen"}) << "\n";
            return kUsage;
        } else {
            dir = a;
        }
    }
    if (regen == check) {
        std::cerr << "ps11: golden needs exactly one of --check or --regen\n";
        return kUsage;
    }
    std::string root = projectDir();
    if (root.empty()) {
        std::cerr << "ps11: golden: cannot find the project folder (tests/shaders)\n";
        return kUserError;
    }
    if (dir.empty()) dir = root + "/tests/golden";
    std::string corpus = root + "/tests/shaders/corpus";
    std::vector<std::string> shaders = listFiles(corpus, ".psh");
    if (shaders.empty()) {
        std::cerr << "ps11: golden: no shaders under " << corpus << "\n";
        return kUserError;
    }
    int failures = 0, written = 0;
    std::set<std::string> expected;
    for (const std::string& path : shaders) {
        std::string rel = path.substr(corpus.size() + 1);
        std::string goldenPath = dir + "/disasm/" + rel + ".txt";
        expected.insert(std::filesystem::path(goldenPath).lexically_normal().string());
        std::string problem;
        std::optional<std::string> text = goldenText(path, rel, problem);
        if (!text) {
            std::cerr << path << ": " << problem << "\n";
            ++failures;
            continue;
        }
        if (regen) {
            std::error_code ec;
            std::filesystem::create_directories(std::filesystem::path(goldenPath).parent_path(), ec);
            std::optional<std::string> old;
            if (std::filesystem::exists(goldenPath, ec)) old = readFile(goldenPath);
            if (!old || *old != *text) {
                if (!writeFile(goldenPath, *text)) return kUserError;
                ++written;
            }
            continue;
        }
        std::error_code ec;
        if (!std::filesystem::exists(goldenPath, ec)) {
            std::cerr << goldenPath << ": missing golden file for " << path << " (run ps11 golden --regen)\n";
            ++failures;
            continue;
        }
        std::optional<std::string> golden = readFile(goldenPath);
        if (!golden || *golden != *text) {
            std::cerr << goldenPath << ": differs from the disassembly of " << path << "\n--- golden\n"
                      << (golden ? *golden : "") << "--- now\n"
                      << *text;
            ++failures;
        }
    }
    // Golden files whose shader is gone are stale.
    for (const std::string& g : listFiles(dir + "/disasm", ".txt")) {
        if (!expected.count(std::filesystem::path(g).lexically_normal().string())) {
            if (regen) {
                std::error_code ec;
                std::filesystem::remove(g, ec);
                std::cout << g << ": removed (no corpus shader)\n";
            } else {
                std::cerr << g << ": stale golden file (no corpus shader; run ps11 golden --regen)\n";
                ++failures;
            }
        }
    }
    if (regen)
        std::cout << shaders.size() << " shaders, " << written << " golden files written, " << failures << " failed\n";
    else
        std::cout << shaders.size() << " shaders: " << (shaders.size() - size_t(failures))
                  << " match their golden disassembly and round-trip, " << failures << " failed\n";
    return failures ? kUserError : kOk;
}

}  // namespace ps11::cli
