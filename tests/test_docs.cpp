// Keeps docs/ true to the code: the ISA table equals what the opcode table generates, and
// every diagnostic code used in the sources is documented in docs/diagnostics.md.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "ps11/isa_doc.h"

namespace {

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

}  // namespace

TEST_CASE("docs: isa.md holds the generated opcode table", "[docs]") {
    std::string page = slurp(std::filesystem::path(PS11_SOURCE_DIR) / "docs" / "isa.md");
    std::string table = ps11::isaMarkdownTable();
    INFO("regenerate with: ./build/ps11 isa > table and paste it into docs/isa.md\n" << table);
    CHECK(page.find(table) != std::string::npos);
}

TEST_CASE("docs: every diagnostic code in the sources is documented", "[docs]") {
    namespace fs = std::filesystem;
    std::string doc = slurp(fs::path(PS11_SOURCE_DIR) / "docs" / "diagnostics.md");
    REQUIRE_FALSE(doc.empty());
    std::regex code("\"(P[1-3][0-9]{3})\"");
    std::set<std::string> missing;
    size_t seen = 0;
    for (const char* dir : {"ps11", "tools"}) {
        for (const auto& entry : fs::directory_iterator(fs::path(PS11_SOURCE_DIR) / dir)) {
            if (entry.path().extension() != ".cpp" && entry.path().extension() != ".h") continue;
            std::string src = slurp(entry.path());
            for (auto it = std::sregex_iterator(src.begin(), src.end(), code); it != std::sregex_iterator(); ++it) {
                ++seen;
                std::string c = (*it)[1];
                if (doc.find("| " + c + " |") == std::string::npos && doc.find("| `" + c + "` |") == std::string::npos)
                    missing.insert(c);
            }
        }
    }
    CHECK(seen > 20);
    std::string list;
    for (const std::string& c : missing) list += c + " ";
    INFO("undocumented codes: " << list);
    CHECK(missing.empty());
}
