// The JSON the libraries and commands print (ps11/json_internal.h): names JSON must escape, NaN
// and infinities, the line layout, and the two library outputs (statsToJson, fitsReportJson)
// read back with nlohmann-json.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "glare/report.h"
#include "ps11/assembler.h"
#include "ps11/json_internal.h"
#include "ps11/validator.h"

namespace {

// Every byte JSON must escape, a byte that is not UTF-8 (Latin-1 é) and a multi-byte character.
const std::string kOdd = std::string("q\"uo\\te/\n\r\t\b\f") + '\x01' + '\x1f' + "lat\xe9 \xc3\xa9nd";
// What a reader gets back: the bad byte as U+FFFD.
const std::string kOddRead = std::string("q\"uo\\te/\n\r\t\b\f") + '\x01' + '\x1f' + "lat\xef\xbf\xbd \xc3\xa9nd";

}  // namespace

TEST_CASE("json: numbers: NaN and infinities are null, integers stay integers", "[json]") {
    using ps11::json::number;
    using ps11::json::rounded;
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    CHECK(number(nan).is_null());
    CHECK(number(inf).is_null());
    CHECK(number(-inf).is_null());
    CHECK(rounded(nan, "%.3f").is_null());
    CHECK(rounded(inf, "%g").is_null());
    CHECK(number(3.0).dump() == "3");
    CHECK(number(-0.5).dump() == "-0.5");
    CHECK(rounded(0.123456789, "%.4f").dump() == "0.1235");
    CHECK(rounded(2.0 / 3.0, "%g").dump() == "0.666667");
    CHECK(rounded(65504.0, "%g").dump() == "65504");
    ps11::json::Json j = {{"nan", number(nan)}, {"x", rounded(1.25, "%.3f")}};
    CHECK(ps11::json::dump(j) == R"({"nan": null, "x": 1.25})");
}

TEST_CASE("json: dump escapes every name and keeps the line layout", "[json]") {
    using ps11::json::Json;
    Json j;
    j[kOdd] = kOdd;
    j["list"] = Json::array({Json{{"name", kOdd}, {"n", 1}}, Json{{"name", "b"}, {"pair", {1, 2}}}});
    j["pair"] = {1, 2};
    for (int depth : {0, 1, 2, 3}) {
        const std::string text = ps11::json::dump(j, depth);
        INFO(depth << ": " << text);
        REQUIRE(nlohmann::json::accept(text));
        const nlohmann::ordered_json back = nlohmann::ordered_json::parse(text);
        CHECK(back[kOddRead] == kOddRead);
        CHECK(back["list"][0]["name"] == kOddRead);
        CHECK(back["pair"] == nlohmann::ordered_json({1, 2}));
        CHECK(back.begin().key() == kOddRead);  // key order kept
    }
    // depth 0: one line; 2: the top object and the list broken, the records and pairs inline.
    CHECK(ps11::json::dump(j, 0).find('\n') == std::string::npos);
    const std::string two = ps11::json::dump(j, 2);
    CHECK(two.find("\n  \"list\": [\n    {\"name\": ") != std::string::npos);
    CHECK(two.find("\"pair\": [1, 2]}\n  ],\n  \"pair\": [1, 2]\n}") != std::string::npos);
    CHECK(ps11::json::dump(Json::array()) == "[]");
    CHECK(ps11::json::dump(Json::object(), 3) == "{}");
    CHECK(ps11::json::dumpCompact(j["list"][1]) == R"({"name":"b","pair":[1,2]})");
}

TEST_CASE("json: check --json statistics: odd instruction text read back", "[json][validator]") {
    ps11::Diagnostics diags;
    ps11::ShaderStats stats;
    std::optional<ps11::Program> p = ps11::parseAssembly("ps_1_1\ntex t0\nmul r0, t0, v0\n", "a.psh", {}, diags);
    REQUIRE(p);
    ps11::validate(*p, diags, &stats);
    REQUIRE(stats.table.size() == 2);
    stats.table[1].text = kOdd;
    const std::string text = ps11::statsToJson(stats);
    INFO(text);
    REQUIRE(nlohmann::json::accept(text));
    const nlohmann::ordered_json j = nlohmann::ordered_json::parse(text);
    CHECK(j["instructions"][1]["text"] == kOddRead);
    CHECK(j["arithSlots"] == 1);
    CHECK(j.begin().key() == "version");
    CHECK(text.find(' ') == text.find(" t0"));  // compact: the only spaces are the instructions'
}

TEST_CASE("json: glare --report --json: odd names read back, numbers and layout as before", "[glare][json]") {
    glare::FitsReport r;
    r.width = 64;
    r.height = 36;
    r.hardware = kOdd;
    glare::PassFit f;
    f.technique = f.preset = f.pass = f.shader = f.version = f.note = kOdd;
    f.constants = {0, 3};
    f.width = 16;
    f.height = 9;
    f.fits = false;
    r.passes = {f, glare::PassFit{}};
    const std::string text = glare::fitsReportJson(r);
    INFO(text);
    REQUIRE(nlohmann::json::accept(text));
    const nlohmann::ordered_json j = nlohmann::ordered_json::parse(text);
    CHECK(j["frame"] == nlohmann::ordered_json({64, 36}));
    CHECK(j["hardware"] == kOddRead);
    REQUIRE(j["passes"].size() == 2);
    for (const char* k : {"technique", "preset", "pass", "shader", "version", "note"})
        CHECK(j["passes"][0][k] == kOddRead);
    CHECK(j["passes"][0]["constants"] == nlohmann::ordered_json({0, 3}));
    CHECK(j["passes"][0]["target"] == nlohmann::ordered_json({16, 9}));
    CHECK(j["passes"][0]["fits_ps_1_1"] == false);
    CHECK(j["passes"][1]["fits_ps_1_1"] == true);
    // The layout of before: the frame on the first line, one pass per line.
    CHECK(text.rfind("{\n  \"frame\": [64, 36],\n  \"hardware\": ", 0) == 0);
    CHECK(text.find("\n    {\"technique\": \"\", \"preset\": \"\", \"pass\": \"\", \"kind\": \"shader\"") !=
          std::string::npos);
    CHECK(text.ends_with("\"note\": \"\"}\n  ]\n}\n"));
}
