// Native reference vectors: assembles every record of tests/golden/native_vectors.txt and
// requires the token stream Microsoft's assembler produced, word for word; every record of
// tests/golden/native_failures.txt must be rejected by the parser or the validator; every
// shader of tests/shaders/corpus must assemble and validate cleanly.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/decoder.h"
#include "ps11/disassembler.h"
#include "ps11/diagnostics.h"
#include "ps11/encoder.h"
#include "ps11/validator.h"

namespace {

// One record of native_vectors.txt / native_failures.txt.
struct Record {
    std::string header;               // the '@' line without the '@'
    std::string source;               // assembly text, lines joined with '\n'
    std::vector<uint32_t> words;      // expected tokens ('=' lines)
    std::string reason;               // '!' line (failures file)
    int line = 0;                     // line of the '@' in the data file

    bool hasTag(const std::string& tag) const {
        return header.find("[" + tag + "]") != std::string::npos;
    }
};

std::string dataPath(const char* rel) { return std::string(PS11_SOURCE_DIR) + "/" + rel; }

std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Reads the record format described at the top of native_vectors.txt. Lines starting with
// '#' outside a record are file comments; inside a record every line up to the first '=' or
// '!' line is source text (so ';' and '//' comments in shaders are kept).
std::vector<Record> readRecords(const std::string& path) {
    std::vector<Record> records;
    std::ifstream in(path);
    std::string line;
    Record* cur = nullptr;
    bool inBody = false;  // still reading source lines
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) {
            cur = nullptr;
            continue;
        }
        if (line[0] == '@') {
            records.push_back({});
            cur = &records.back();
            cur->header = line.substr(1);
            cur->line = lineNo;
            inBody = true;
            continue;
        }
        if (!cur) continue;  // file comment
        if (line[0] == '=') {
            inBody = false;
            std::istringstream ws(line.substr(1));
            std::string w;
            while (ws >> w) cur->words.push_back(static_cast<uint32_t>(std::stoul(w, nullptr, 16)));
            continue;
        }
        if (line[0] == '!') {
            inBody = false;
            cur->reason = line.substr(1);
            continue;
        }
        if (inBody) cur->source += line + "\n";
    }
    return records;
}

std::string hexStream(const std::vector<uint32_t>& words) {
    std::string s;
    char buf[12];
    for (size_t i = 0; i < words.size(); ++i) {
        std::snprintf(buf, sizeof buf, "%s%08x", i ? " " : "", static_cast<unsigned>(words[i]));
        s += buf;
    }
    return s;
}

// Assembles `text`; nullopt plus the diagnostics text when parsing fails.
std::optional<ps11::Program> assemble(const std::string& text, const std::string& name,
                                      ps11::Diagnostics& diags) {
    ps11::AssembleOptions options;
    return ps11::parseAssembly(text, name, options, diags);
}

}  // namespace

TEST_CASE("native vectors encode word for word", "[native][encoder]") {
    const auto records = readRecords(dataPath("tests/golden/native_vectors.txt"));
    REQUIRE(records.size() >= 70);

    std::vector<std::string> failures;
    for (const auto& rec : records) {
        ps11::Diagnostics diags;
        const std::string name = "native_vectors.txt:" + std::to_string(rec.line);
        auto program = assemble(rec.source, name, diags);
        if (!program) {
            failures.push_back(name + " @" + rec.header + "\n  parse failed:\n" + diags.formatAll() +
                               "  source:\n" + rec.source);
            continue;
        }
        const std::vector<uint32_t> got = ps11::encode(*program);
        if (got != rec.words) {
            failures.push_back(name + " @" + rec.header + "\n  source:\n" + rec.source +
                               "  expected: " + hexStream(rec.words) + "\n  got:      " + hexStream(got));
        }
    }
    for (const auto& f : failures) UNSCOPED_INFO(f);
    INFO(failures.size() << " of " << records.size() << " vectors differ");
    CHECK(failures.empty());
}

TEST_CASE("native vectors accepted by the native runtime validate", "[native][validator]") {
    const auto records = readRecords(dataPath("tests/golden/native_vectors.txt"));
    std::vector<std::string> failures;
    size_t checked = 0;
    for (const auto& rec : records) {
        // asm.c streams were assembled with validation skipped; hand-edited streams are not
        // assembler output. Only streams the native runtime accepted are checked here.
        if (rec.hasTag("unvalidated") || rec.hasTag("hand-edited")) continue;
        ++checked;
        ps11::Diagnostics diags;
        const std::string name = "native_vectors.txt:" + std::to_string(rec.line);
        auto program = assemble(rec.source, name, diags);
        if (!program) {
            failures.push_back(name + " @" + rec.header + "\n  parse failed:\n" + diags.formatAll());
            continue;
        }
        if (!ps11::validate(*program, diags)) {
            failures.push_back(name + " @" + rec.header + "\n  source:\n" + rec.source + diags.formatAll());
        }
    }
    for (const auto& f : failures) UNSCOPED_INFO(f);
    INFO(failures.size() << " of " << checked << " runtime-accepted vectors fail validation");
    CHECK(checked > 0);
    CHECK(failures.empty());
}

TEST_CASE("native failure cases are rejected", "[native][validator]") {
    const auto records = readRecords(dataPath("tests/golden/native_failures.txt"));
    REQUIRE(records.size() >= 10);

    std::vector<std::string> accepted;
    for (const auto& rec : records) {
        ps11::Diagnostics diags;
        const std::string name = "native_failures.txt:" + std::to_string(rec.line);
        auto program = assemble(rec.source, name, diags);
        if (!program) {
            CHECK(diags.hasErrors());  // a failed parse must say why
            continue;
        }
        const bool valid = ps11::validate(*program, diags);
        if (valid || !diags.hasErrors()) {
            accepted.push_back(name + " @" + rec.header + "\n  expected rejection:" + rec.reason +
                               "\n  source:\n" + rec.source + "  tokens: " +
                               hexStream(ps11::encode(*program)));
        }
    }
    for (const auto& a : accepted) UNSCOPED_INFO(a);
    INFO(accepted.size() << " of " << records.size() << " failure cases were accepted");
    CHECK(accepted.empty());
}

TEST_CASE("shader corpus assembles and validates", "[native][corpus]") {
    namespace fs = std::filesystem;
    const fs::path root = dataPath("tests/shaders/corpus");
    REQUIRE(fs::exists(root));

    std::vector<std::string> failures;
    size_t count = 0;
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
        if (!entry.is_regular_file() || entry.path().extension() != ".psh") continue;
        ++count;
        const std::string path = entry.path().string();
        ps11::Diagnostics diags;
        auto program = assemble(readText(path), path, diags);
        if (!program) {
            failures.push_back(path + ": parse failed\n" + diags.formatAll());
            continue;
        }
        // The folder name is the version the shader is written for.
        const std::string folder = entry.path().parent_path().filename().string();
        const std::string expect = "ps_1_" + std::to_string(program->version.minor);
        if (program->version.major != 1 || folder != expect) {
            failures.push_back(path + ": version " + std::to_string(program->version.major) + "." +
                               std::to_string(program->version.minor) + " does not match folder " + folder);
        }
        if (!ps11::validate(*program, diags)) failures.push_back(path + ": invalid\n" + diags.formatAll());
    }
    for (const auto& f : failures) UNSCOPED_INFO(f);
    INFO(failures.size() << " of " << count << " corpus shaders failed");
    CHECK(count >= 60);
    CHECK(failures.empty());
}

// The round-trip property on every native vector: text → tokens → text → tokens gives the
// same tokens, and the native words themselves decode and print back to those words.
TEST_CASE("native vectors round-trip through the disassembler", "[native][roundtrip]") {
    const auto records = readRecords(dataPath("tests/golden/native_vectors.txt"));
    REQUIRE(records.size() >= 70);
    size_t checked = 0;
    std::string failures;
    for (const Record& rec : records) {
        ps11::Diagnostics d1;
        ps11::Diagnostics d2;
        std::optional<ps11::Program> decoded = ps11::decode(rec.words, 0, d1);
        if (!decoded) {
            failures += rec.header + ": native words do not decode:\n" + d1.formatAll();
            continue;
        }
        std::string text = ps11::disassemble(*decoded);
        std::optional<ps11::Program> again = ps11::parseAssembly(text, "roundtrip.psh", {}, d2);
        if (!again) {
            failures += rec.header + ": disassembly does not assemble:\n" + text + d2.formatAll();
            continue;
        }
        if (ps11::encode(*again) != rec.words) failures += rec.header + ": round trip changed the tokens\n" + text;
        ++checked;
    }
    INFO(failures);
    CHECK(failures.empty());
    CHECK(checked == records.size());
}
