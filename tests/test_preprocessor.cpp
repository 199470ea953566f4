// Unit tests for the preprocessor stage (ps11/preprocessor.h): macros, conditionals, includes,
// comments, column mapping, every P10xx diagnostic and the resource limits.
#include <catch2/catch.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>

#include "ps11/preprocessor.h"

using namespace ps11;

namespace {

struct Run {
    Diagnostics diags;
    std::vector<PreprocessedLine> lines;

    // Non-blank output lines' text.
    std::vector<std::string> texts() const {
        std::vector<std::string> out;
        for (const PreprocessedLine& l : lines) {
            std::string t = l.text;
            while (!t.empty() && (t.back() == ' ' || t.back() == '\t')) t.pop_back();
            if (!t.empty()) out.push_back(t);
        }
        return out;
    }
    std::string joined() const {
        std::string s;
        for (const std::string& t : texts()) s += t + "\n";
        return s;
    }
    const Diagnostic* find(std::string_view code) const {
        for (const Diagnostic& d : diags.all())
            if (d.code == code) return &d;
        return nullptr;
    }
};

Run pp(std::string_view src, PreprocessOptions opts = {}, const std::map<std::string, std::string>& files = {}) {
    Run r;
    if (!opts.readFile) {
        opts.readFile = [files](const std::string& path) -> std::optional<std::string> {
            auto it = files.find(path);
            if (it == files.end()) return std::nullopt;
            return it->second;
        };
    }
    r.lines = preprocess(src, "main.psh", opts, r.diags);
    return r;
}

}  // namespace

TEST_CASE("preprocessor: plain text passes through with line numbers and columns", "[preprocessor]") {
    Run r = pp("ps_1_1\ntex t0\nmov r0, t0\n");
    REQUIRE(r.lines.size() == 3);
    CHECK(r.lines[1].text == "tex t0");
    CHECK(r.lines[2].line == 3);
    CHECK(r.lines[2].columns.size() == r.lines[2].text.size());
    CHECK(r.lines[2].columns[4] == 5);
    CHECK(r.diags.all().empty());
    CHECK(r.diags.fileName(r.lines[0].fileId) == "main.psh");
}

TEST_CASE("preprocessor: empty input and missing final newline", "[preprocessor]") {
    CHECK(pp("").lines.empty());
    Run r = pp("mov r0, v0");
    REQUIRE(r.lines.size() == 1);
    CHECK(r.lines[0].text == "mov r0, v0");
}

TEST_CASE("preprocessor: CRLF line ends and BOM", "[preprocessor]") {
    Run r = pp("\xEF\xBB\xBFps_1_1\r\n#define X v0\r\nmov r0, X\r\n");
    REQUIRE(r.lines.size() == 2);
    CHECK(r.lines[0].text == "ps_1_1");
    CHECK(r.lines[1].text == "mov r0, v0");
    CHECK(r.lines[1].line == 3);
}

TEST_CASE("preprocessor: object-like macros and #undef", "[preprocessor]") {
    Run r = pp("#define SRC t0\n#define DST r0\nmov DST, SRC\n#undef SRC\nmov DST, SRC\n");
    CHECK(r.texts() == std::vector<std::string>{"mov r0, t0", "mov r0, SRC"});
    CHECK_FALSE(r.diags.hasErrors());
}

TEST_CASE("preprocessor: identifiers are whole tokens", "[preprocessor]") {
    Run r = pp("#define r0 r1\n#define x w\nmov r0.x, r01.x\nmov r0_bx2, c0.xyz\n");
    CHECK(r.texts() == std::vector<std::string>{"mov r1.w, r01.w", "mov r0_bx2, c0.xyz"});
}

TEST_CASE("preprocessor: function-like macros typical of engine shaders", "[preprocessor]") {
    Run r =
        pp("#define BLEND(d,a,b) lrp d, c0, a, b\n"
           "#define SAMPLE(n) tex t##n\n"
           "#define MADD(d, a, b, c) mad d, a, b, c\n"
           "SAMPLE(0)\n"
           "SAMPLE( 3 )\n"
           "BLEND(r0, t0, t1)\n"
           "MADD(r0.rgb, r1_bx2, t0, -c2)\n");
    CHECK(r.texts() ==
          std::vector<std::string>{"tex t0", "tex t3", "lrp r0, c0, t0, t1", "mad r0.rgb, r1_bx2, t0, -c2"});
    CHECK_FALSE(r.diags.hasErrors());
}

TEST_CASE("preprocessor: function-like name without '(' is left alone", "[preprocessor]") {
    Run r = pp("#define F(x) x\nmov F, r0\nmov r0, F (v0)\n");
    CHECK(r.texts() == std::vector<std::string>{"mov F, r0", "mov r0, v0"});
}

TEST_CASE("preprocessor: arguments with parentheses, empty arguments, zero parameters", "[preprocessor]") {
    Run r = pp("#define F(a,b) [a|b]\n#define Z() zz\nF((1,2),3)\nF(,)\nZ()\nZ( )\n");
    CHECK(r.texts() == std::vector<std::string>{"[(1,2)|3]", "[|]", "zz", "zz"});
    CHECK_FALSE(r.diags.hasErrors());
}

TEST_CASE("preprocessor: nested and recursive expansion stops at self-reference", "[preprocessor]") {
    Run r =
        pp("#define A B\n#define B A\nA B\n"
           "#define R R + 1\nR\n"
           "#define F(x) F(x) x\nF(1)\n"
           "#define G(x) x\nG(G(G(v0)))\n"
           "#define H G\nH(v1)\n"
           "#define ID(x) x\n#define CALL(f, y) f(y)\nCALL(ID, t2)\n");
    CHECK(r.texts() == std::vector<std::string>{"A B", "R + 1", "F(1) 1", "v0", "v1", "t2"});
    CHECK_FALSE(r.diags.hasErrors());
}

TEST_CASE("preprocessor: arguments are expanded before substitution but not next to ## or #", "[preprocessor]") {
    Run r =
        pp("#define N 2\n#define CAT(a,b) a##b\n#define XCAT(a,b) CAT(a,b)\n#define STR(x) #x\n"
           "CAT(t, N)\nXCAT(t, N)\nSTR(N)\nSTR( a  \"b\"  c )\n");
    CHECK(r.texts() == std::vector<std::string>{"tN", "t2", "\"N\"", "\"a \\\"b\\\" c\""});
}

TEST_CASE("preprocessor: ## with empty operands and in object-like macros", "[preprocessor]") {
    Run r = pp("#define P(a,b) x a##b y\n#define O r ## 0\nP(,)\nP(1,)\nP(,2)\nmov O, v0\n");
    CHECK(r.texts() == std::vector<std::string>{"x  y", "x 1 y", "x 2 y", "mov r0, v0"});
}

TEST_CASE("preprocessor: variadic macros", "[preprocessor]") {
    Run r = pp("#define OP(op, ...) op __VA_ARGS__\nOP(mul, r0, t0, t1)\nOP(nop)\n");
    CHECK(r.texts() == std::vector<std::string>{"mul r0, t0, t1", "nop"});
    CHECK_FALSE(r.diags.hasErrors());
}

TEST_CASE("preprocessor: identical redefinition is silent, a different one warns P1013", "[preprocessor]") {
    Run same = pp("#define X  1 +  2\n#define X 1 + 2\n");
    CHECK(same.diags.all().empty());
    Run diff = pp("#define X 1\n#define X 2\nX\n");
    REQUIRE(diff.find("P1013"));
    CHECK(diff.find("P1013")->severity == Severity::Warning);
    CHECK(diff.find("P1013")->loc.line == 2);
    CHECK_FALSE(diff.diags.hasErrors());
    CHECK(diff.texts() == std::vector<std::string>{"2"});
}

TEST_CASE("preprocessor: -D defines", "[preprocessor]") {
    PreprocessOptions o;
    o.defines = {{"HQ", "1"}, {"EMPTY", ""}, {"REG", "r1"}, {"F(x)", "x.a"}};
    Run r = pp("#if HQ\nhq\n#endif\n[EMPTY]\nmov REG, F(t0)\n#ifdef EMPTY\nyes\n#endif\n", o);
    CHECK(r.texts() == std::vector<std::string>{"hq", "[]", "mov r1, t0.a", "yes"});
    CHECK_FALSE(r.diags.hasErrors());

    PreprocessOptions bad;
    bad.defines = {{"1X", "1"}};
    Run b = pp("x\n", bad);
    REQUIRE(b.find("P1005"));
    CHECK(b.diags.fileName(b.find("P1005")->loc.fileId) == "<command line>");
}

TEST_CASE("preprocessor: comments are blanked, columns and line count kept", "[preprocessor]") {
    Run r = pp("mov r0, v0 // copy\nadd /* a */ r0, r0, v1\nmul r0, /* multi\nline\ncomment */ r0, c0\n");
    REQUIRE(r.lines.size() == 5);
    CHECK(r.lines[0].text == "mov r0, v0        ");
    CHECK(r.lines[1].text == "add         r0, r0, v1");
    CHECK(r.lines[1].columns[12] == 13);
    CHECK(r.lines[2].text == "mul r0,         ");
    CHECK(r.lines[3].text == "    ");
    CHECK(r.lines[3].line == 4);
    CHECK(r.lines[4].text == "           r0, c0");
    CHECK(r.lines[4].line == 5);
    CHECK(r.lines[4].columns[11] == 12);
}

TEST_CASE("preprocessor: ';' comments are kept verbatim and not expanded", "[preprocessor]") {
    Run r = pp("#define X v0\nmov r0, X ; X isn't /* expanded\nmov r1, X ; don't // strip\n");
    CHECK(r.texts() == std::vector<std::string>{"mov r0, v0 ; X isn't /* expanded", "mov r1, v0 ; don't // strip"});
    CHECK_FALSE(r.diags.hasErrors());
}

TEST_CASE("preprocessor: quotes are ordinary characters", "[preprocessor]") {
    Run r = pp("#define X 1\nX 'X' \"X\"\n");
    CHECK(r.texts() == std::vector<std::string>{"1 '1' \"1\""});
}

TEST_CASE("preprocessor: line continuation", "[preprocessor]") {
    Run r =
        pp("#define BLEND(d, a, b) \\\n    lrp d, c0, \\\n        a, b\nBLEND(r0, t0, t1)\nmov r0, \\\r\n v0\nend\n");
    REQUIRE(r.lines.size() == 3);
    CHECK(r.lines[0].text == "lrp r0, c0, t0, t1");
    CHECK(r.lines[0].line == 4);
    CHECK(r.lines[1].text == "mov r0,  v0");
    CHECK(r.lines[1].line == 5);
    CHECK(r.lines[2].line == 7);
}

TEST_CASE("preprocessor: directives with whitespace around '#' and comments inside", "[preprocessor]") {
    Run r = pp("  #  define X 1\n\t#\tifdef X /* c */\nyes\n # endif\n#\n#define Y 2 /* multi\n line */ + 3\nY\n");
    CHECK(r.texts() == std::vector<std::string>{"yes", "2 + 3"});
    CHECK(r.diags.all().empty());
}

TEST_CASE("preprocessor: column map points macro bytes at the macro name", "[preprocessor]") {
    Run r = pp("#define SRC t0_bx2\n#define BLEND(d,a,b) lrp d, c0, a, b\nmov r0,   SRC\n  BLEND(r0, t0, t1)\n");
    REQUIRE(r.lines.size() == 2);
    const PreprocessedLine& a = r.lines[0];
    CHECK(a.text == "mov r0,   t0_bx2");
    REQUIRE(a.columns.size() == a.text.size());
    CHECK(a.columns[0] == 1);
    CHECK(a.columns[10] == 11);
    CHECK(a.columns[15] == 11);
    const PreprocessedLine& b = r.lines[1];
    CHECK(b.text == "  lrp r0, c0, t0, t1");
    REQUIRE(b.columns.size() == b.text.size());
    CHECK(b.columns[2] == 3);  // 'lrp' comes from the macro body: BLEND's column
    CHECK(b.columns[b.text.find("c0")] == 3);
    CHECK(b.columns[b.text.find("r0")] == 9);  // arguments keep their own columns
    CHECK(b.columns[b.text.find("t0")] == 13);
    CHECK(b.columns[b.text.find("t1")] == 17);
    SourceLoc loc = b.locAt(b.text.find("t1"));
    CHECK(loc.line == 4);
    CHECK(loc.col == 17);
    CHECK(b.locAt(1000).col == b.columns.back() + 1);
    CHECK(PreprocessedLine{}.locAt(0).col == 1);
}

TEST_CASE("preprocessor: conditionals", "[preprocessor]") {
    Run r =
        pp("#define V 14\n"
           "#if V == 11\nv11\n#elif V == 14\nv14\n#else\nother\n#endif\n"
           "#ifdef V\nd\n#endif\n#ifndef V\nnd\n#else\nnd-else\n#endif\n"
           "#if 0\nskip\n#else\nelse\n#endif\n");
    CHECK(r.texts() == std::vector<std::string>{"v14", "d", "nd-else", "else"});
    CHECK_FALSE(r.diags.hasErrors());
}

TEST_CASE("preprocessor: skipped lines come out blank with their line numbers", "[preprocessor]") {
    Run r = pp("a\n#if 0\nb\nc\n#endif\nd\n");
    REQUIRE(r.lines.size() == 4);
    CHECK(r.lines[1].text.empty());
    CHECK(r.lines[1].line == 3);
    CHECK(r.lines[2].line == 4);
    CHECK(r.lines[3].text == "d");
    CHECK(r.lines[3].line == 6);
}

TEST_CASE("preprocessor: nested conditionals", "[preprocessor]") {
    const char* src =
        "#if A\n"
        "  #if B\nab\n  #else\na!b\n  #endif\n"
        "#elif C\n"
        "  #ifdef B\ncb\n  #elif 1\nc!b\n  #endif\n"
        "#else\n"
        "  #if 1\nnone\n  #endif\n"
        "#endif\n";
    auto with = [&](std::vector<std::pair<std::string, std::string>> d) {
        PreprocessOptions o;
        o.defines = std::move(d);
        return pp(src, o).texts();
    };
    CHECK(with({{"A", "1"}, {"B", "1"}}) == std::vector<std::string>{"ab"});
    CHECK(with({{"A", "1"}}) == std::vector<std::string>{"a!b"});
    CHECK(with({{"C", "1"}, {"B", "1"}}) == std::vector<std::string>{"cb"});
    CHECK(with({{"C", "1"}}) == std::vector<std::string>{"c!b"});
    CHECK(with({}) == std::vector<std::string>{"none"});
}

TEST_CASE("preprocessor: skipped groups ignore unknown directives and bad expressions", "[preprocessor]") {
    Run r = pp("#if 0\n#bogus\n#if 1/0\n#endif\n#error no\n#include \"none\"\n#elif 1\nok\n#elif 1/0\n#endif\n");
    CHECK(r.texts() == std::vector<std::string>{"ok"});
    CHECK(r.diags.all().empty());
}

TEST_CASE("preprocessor: #if expressions", "[preprocessor]") {
    auto value = [](const std::string& e) {
        Run r = pp("#define TWO 2\n#define F(x) ((x) * 2)\n#if " + e + "\n1\n#else\n0\n#endif\n");
        INFO(e << "\n" << r.diags.formatAll());
        CHECK_FALSE(r.diags.hasErrors());
        return r.texts().at(0) == "1";
    };
    CHECK(value("1 + 2 * 3 == 7"));
    CHECK(value("(1 + 2) * 3 == 9"));
    CHECK(value("10 / 3 == 3 && 10 % 3 == 1"));
    CHECK(value("1 << 4 == 16 && 256 >> 4 == 16"));
    CHECK(value("(6 & 3) == 2 && (6 | 3) == 7 && (6 ^ 3) == 5"));
    CHECK(value("~0 == -1 && !0 && !!5 && -(-3) == +3"));
    CHECK(value("1 < 2 && 2 <= 2 && 3 > 2 && 3 >= 3 && 1 != 2"));
    CHECK(value("0 ? 0 : 1"));
    CHECK(value("1 ? 2 ? 1 : 0 : 0"));
    CHECK(value("0x10 == 16 && 010 == 8 && 10u == 10 && 7L == 7"));
    CHECK(value("defined TWO && defined(TWO) && !defined NOPE && !defined ( NOPE )"));
    CHECK(value("UNKNOWN == 0 && TWO == 2 && F(TWO) == 4"));
    CHECK(value("0 && 1 / 0 || 1"));  // short circuit: no division by zero error
    CHECK(value("1 || 1 % 0"));
    CHECK(value("1 ? 1 : 1 / 0"));
    CHECK(value("-9223372036854775807 - 1 < 0"));
    CHECK(value("(-9223372036854775807 - 1) / -1 < 0"));  // wraps, no UB
    CHECK(value("(1 << 64) == 0 && (-8 >> 70) == -1"));
    CHECK_FALSE(value("0"));
    CHECK_FALSE(value("2 - TWO"));
}

TEST_CASE("preprocessor: defined produced by a macro", "[preprocessor]") {
    Run r = pp("#define Y\n#define HAS_Y defined(Y)\n#define HAS_Z defined Z\n#if HAS_Y && !HAS_Z\nyes\n#endif\n");
    CHECK(r.texts() == std::vector<std::string>{"yes"});
    CHECK(r.diags.all().empty());
}

TEST_CASE("preprocessor: #include through the readFile hook", "[preprocessor]") {
    std::map<std::string, std::string> files{
        {"common.inc", "#define BLEND(d,a,b) lrp d, c0, a, b\ndef c0, 0.5, 0.5, 0.5, 0.5\n"},
        {"sub/a.inc", "#include \"b.inc\"\nfrom a\n"},
        {"sub/b.inc", "from b\n"},
        {"lib/l.inc", "from lib\n"},
    };
    PreprocessOptions o;
    o.includeDirs = {"nowhere", "lib/"};
    Run r =
        pp("ps_1_1\n#include \"common.inc\"\n#include <sub/a.inc>\n#include \"l.inc\"\nBLEND(r0, t0, t1)\n", o, files);
    CHECK(r.texts() == std::vector<std::string>{"ps_1_1", "def c0, 0.5, 0.5, 0.5, 0.5", "from b", "from a", "from lib",
                                                "lrp r0, c0, t0, t1"});
    CHECK(r.diags.all().empty());
    REQUIRE(r.lines.size() == 6);
    CHECK(r.diags.fileName(r.lines[1].fileId) == "common.inc");
    CHECK(r.lines[1].line == 2);
    CHECK(r.diags.fileName(r.lines[2].fileId) == "sub/b.inc");
    CHECK(r.diags.fileName(r.lines[4].fileId) == "lib/l.inc");
    CHECK(r.diags.fileName(r.lines[5].fileId) == "main.psh");
    CHECK(r.lines[5].line == 5);
}

TEST_CASE("preprocessor: #include resolves relative to the including file first", "[preprocessor]") {
    std::map<std::string, std::string> files{{"shaders/x.inc", "local\n"}, {"inc/x.inc", "global\n"}};
    PreprocessOptions o;
    o.includeDirs = {"inc"};
    o.readFile = [files](const std::string& p) -> std::optional<std::string> {
        auto it = files.find(p);
        return it == files.end() ? std::nullopt : std::optional<std::string>(it->second);
    };
    Diagnostics d;
    auto lines = preprocess("#include \"x.inc\"\n", "shaders/main.psh", o, d);
    REQUIRE(lines.size() == 1);
    CHECK(lines[0].text == "local");
}

TEST_CASE("preprocessor: computed #include and #pragma once", "[preprocessor]") {
    std::map<std::string, std::string> files{{"once.inc", "#pragma once\nonce\n"}, {"m.inc", "m\n"}};
    Run r = pp("#define FILE \"m.inc\"\n#include FILE\n#include \"once.inc\"\n#include \"once.inc\"\n#pragma foo bar\n",
               {}, files);
    CHECK(r.texts() == std::vector<std::string>{"m", "once"});
    CHECK(r.diags.all().empty());
}

TEST_CASE("preprocessor: #include of a real file on disk", "[preprocessor]") {
    namespace fs = std::filesystem;
    const fs::path dir =
        fs::temp_directory_path() /
        ("ps11_pp_test_" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    fs::create_directories(dir / "inc");
    std::ofstream(dir / "inc" / "disk.inc") << "#define FROM_DISK t3\r\nfrom disk\r\n";
    std::ofstream(dir / "near.inc") << "near\n";
    PreprocessOptions o;
    o.includeDirs = {(dir / "inc").string()};
    Diagnostics d;
    const std::string mainPath = (dir / "main.psh").string();
    auto lines =
        preprocess("#include \"disk.inc\"\n#include \"near.inc\"\ntex FROM_DISK\n#include \"inc\"\n", mainPath, o, d);
    fs::remove_all(dir);
    REQUIRE(lines.size() == 3);
    CHECK(lines[0].text == "from disk");
    CHECK(lines[1].text == "near");
    CHECK(lines[2].text == "tex t3");
    CHECK(d.has("P1003"));  // a directory is not a readable file
    CHECK(d.errorCount() == 1);
}

TEST_CASE("preprocessor: #line renumbers the following lines", "[preprocessor]") {
    Run r = pp("a\n#line 100\nb\nc\n#line 7 \"other.psh\"\nd\n");
    REQUIRE(r.lines.size() == 4);
    CHECK(r.lines[1].line == 100);
    CHECK(r.lines[2].line == 101);
    CHECK(r.lines[3].line == 7);
    CHECK(r.diags.fileName(r.lines[3].fileId) == "other.psh");
    CHECK(pp("#line x\n").diags.has("P1014"));
    CHECK(pp("#line 5 junk\n").diags.has("P1014"));
}

// ---- Diagnostics --------------------------------------------------------------------------

TEST_CASE("preprocessor: P1001 unterminated #if", "[preprocessor][diag]") {
    Run r = pp("a\n  #ifdef X\nb\n");
    const Diagnostic* d = r.find("P1001");
    REQUIRE(d);
    CHECK(d->loc.line == 2);
    CHECK(d->loc.col == 3);
    CHECK(d->message.find("#ifdef") != std::string::npos);
    // Conditionals must close in the file that opened them.
    Run inc = pp("#include \"a.inc\"\n#endif\n", {}, {{"a.inc", "#if 1\n"}});
    CHECK(inc.diags.has("P1001"));
    CHECK(inc.diags.has("P1002"));
}

TEST_CASE("preprocessor: P1002 #else/#elif/#endif without #if or after #else", "[preprocessor][diag]") {
    CHECK(pp("#endif\n").diags.has("P1002"));
    CHECK(pp("#else\n").diags.has("P1002"));
    CHECK(pp("#elif 1\n").diags.has("P1002"));
    Run r = pp("#if 0\n#else\nx\n#else\ny\n#elif 1\nz\n#endif\n");
    CHECK(r.diags.errorCount() == 2);
    CHECK(r.find("P1002")->loc.line == 4);
    CHECK(r.texts() == std::vector<std::string>{"x"});
}

TEST_CASE("preprocessor: P1003 include not found", "[preprocessor][diag]") {
    PreprocessOptions o;
    o.includeDirs = {"a", "b"};
    Run r = pp("\n#include \"missing.inc\"\n", o);
    const Diagnostic* d = r.find("P1003");
    REQUIRE(d);
    CHECK(d->loc.line == 2);
    CHECK(d->loc.col == 10);
    CHECK(d->message.find("missing.inc") != std::string::npos);
    CHECK(d->message.find("b/missing.inc") != std::string::npos);
}

TEST_CASE("preprocessor: P1004 recursive include and include depth", "[preprocessor][diag]") {
    Run self = pp("#include \"main.psh\"\n", {}, {{"main.psh", "x\n"}});
    CHECK(self.diags.has("P1004"));
    Run loop = pp("#include \"a.inc\"\n", {},
                  {{"a.inc", "#include \"./b.inc\"\n"}, {"./b.inc", "#include \"a.inc\"\n"}, {"./a.inc", "x\n"}});
    CHECK(loop.diags.has("P1004"));
    CHECK(loop.diags.errorCount() == 1);

    // A chain of distinct files deeper than maxIncludeDepth.
    PreprocessOptions o;
    o.maxIncludeDepth = 5;
    o.readFile = [](const std::string& p) -> std::optional<std::string> { return "#include \"" + p + "x\"\n"; };
    Diagnostics d;
    preprocess("#include \"f\"\n", "main.psh", o, d);
    CHECK(d.has("P1004"));
    CHECK(d.errorCount() == 1);
}

TEST_CASE("preprocessor: include fan-out stays bounded", "[preprocessor][diag]") {
    // Each file includes two new ones: 2^depth files without a limit.
    PreprocessOptions o;
    o.readFile = [](const std::string& p) -> std::optional<std::string> {
        return "#include \"" + p + "a\"\n#include \"" + p + "b\"\nline\n";
    };
    Diagnostics d;
    auto lines = preprocess("#include \"f\"\n", "main.psh", o, d);
    CHECK(d.has("P1004"));
    CHECK(lines.size() < 10000);
}

TEST_CASE("preprocessor: P1005 bad #define and #undef", "[preprocessor][diag]") {
    for (const char* src : {"#define\n", "#define 1X\n", "#define defined 1\n", "#define F(a,a) a\n", "#define F(a\n",
                            "#define F(a b) a\n", "#define F(1) a\n", "#define F(..., a) a\n", "#define X ## a\n",
                            "#define X a ##\n", "#define F(a) #b\n", "#undef\n", "#undef 3\n"}) {
        Run r = pp(src);
        INFO(src);
        CHECK(r.diags.has("P1005"));
    }
    Run r = pp("#define   (x) x\n");
    REQUIRE(r.find("P1005"));
    CHECK(r.find("P1005")->loc.col == 11);
    // A bad definition defines nothing.
    CHECK(pp("#define F(a,a) a\nF(1,2)\n").texts() == std::vector<std::string>{"F(1,2)"});
}

TEST_CASE("preprocessor: P1006 bad #if expressions", "[preprocessor][diag]") {
    for (const char* e : {"", "1 +", "(1", "1 )", "1 ? 2", "1.5", "08", "0x", "'a'", "defined", "defined(X",
                          "defined 3", "1 2", "1 / 0", "5 % (2 - 2)", "\"s\""}) {
        Run r = pp(std::string("#if ") + e + "\nx\n#endif\n");
        INFO(e);
        CHECK(r.diags.has("P1006"));
        CHECK(r.texts().empty());
    }
    Run r = pp("#if 1 / 0\n#endif\n");
    REQUIRE(r.find("P1006"));
    CHECK(r.find("P1006")->message.find("division by zero") != std::string::npos);
    CHECK(r.find("P1006")->loc.col == 7);
    CHECK(pp("#if 0\n#elif 1/0\n#endif\n").diags.has("P1006"));
}

TEST_CASE("preprocessor: P1006 deeply nested expressions do not overflow the stack", "[preprocessor][diag]") {
    CHECK(pp("#if " + std::string(100000, '(') + "1\n#endif\n").diags.has("P1006"));
    CHECK(pp("#if " + std::string(100000, '!') + "1\n#endif\n").diags.has("P1006"));
    std::string chain = "#if 1";
    for (int i = 0; i < 20000; ++i) chain += " ? 1 : 1";
    CHECK(pp(chain + "\n#endif\n").diags.has("P1006"));
    // Within the limit it is fine.
    CHECK_FALSE(pp("#if " + std::string(100, '(') + "1" + std::string(100, ')') + "\n#endif\n").diags.hasErrors());
}

TEST_CASE("preprocessor: P1007 #error", "[preprocessor][diag]") {
    Run r = pp("#ifndef PS_1_4\n  #error needs ps_1_4 (don't run)  \n#endif\n");
    const Diagnostic* d = r.find("P1007");
    REQUIRE(d);
    CHECK(d->message == "#error needs ps_1_4 (don't run)");
    CHECK(d->loc.line == 2);
    CHECK(d->loc.col == 3);
    CHECK(r.diags.format(*d) == "main.psh:2:3: error P1007: #error needs ps_1_4 (don't run)");
}

TEST_CASE("preprocessor: P1008 unknown directive", "[preprocessor][diag]") {
    Run r = pp("#foo bar\n# 12\n##define X\n");
    CHECK(r.diags.errorCount() == 3);
    CHECK(r.find("P1008")->message.find("#foo") != std::string::npos);
    CHECK(r.find("P1008")->loc.col == 2);
    // A huge directive name or #error text is quoted as a short excerpt.
    const std::string huge(1 << 20, 'q');
    Run big = pp("#" + huge + "\n#error " + huge + "\n");
    REQUIRE(big.find("P1008"));
    CHECK(big.find("P1008")->message.size() < 120);
    CHECK(big.find("P1008")->message.find("…'") != std::string::npos);
    REQUIRE(big.find("P1007"));
    CHECK(big.find("P1007")->message.size() < 250);
    CHECK(big.find("P1007")->loc.line == 2);
}

TEST_CASE("preprocessor: P1009 macro argument count mismatch", "[preprocessor][diag]") {
    Run r = pp("#define BLEND(d,a,b) lrp d, c0, a, b\n#define Z() z\nmov r0, BLEND(r0, t0)\nZ(1)\n");
    const Diagnostic* d = r.find("P1009");
    REQUIRE(d);
    CHECK(d->loc.line == 3);
    CHECK(d->loc.col == 9);
    CHECK(d->message.find("expects 3 arguments, got 2") != std::string::npos);
    CHECK(r.diags.errorCount() == 2);
    CHECK(pp("#define V(a, ...) a\nV()\n").diags.errorCount() == 0);  // V() is one empty argument
    CHECK(pp("#define V(a, b, ...) a\nV(1)\n").diags.has("P1009"));
}

TEST_CASE("preprocessor: P1010 unterminated comment", "[preprocessor][diag]") {
    Run r = pp("mov r0, v0\n  add /* never\nclosed\n");
    const Diagnostic* d = r.find("P1010");
    REQUIRE(d);
    CHECK(d->loc.line == 2);
    CHECK(d->loc.col == 7);
    // Comments do not run from an included file into the includer.
    Run inc = pp("#include \"a.inc\"\nafter\n", {}, {{"a.inc", "/* open\n"}});
    CHECK(inc.diags.has("P1010"));
    CHECK(inc.texts() == std::vector<std::string>{"after"});
}

TEST_CASE("preprocessor: P1011 unterminated macro argument list", "[preprocessor][diag]") {
    Run r = pp("#define F(x) x\n  F(1, (2)\nF(a ; b)\n");
    CHECK(r.diags.errorCount() == 2);
    const Diagnostic* d = r.find("P1011");
    REQUIRE(d);
    CHECK(d->loc.line == 2);
    CHECK(d->loc.col == 3);
}

TEST_CASE("preprocessor: P1012 expansion limits", "[preprocessor][diag]") {
    // Exponential growth: each level doubles.
    std::string src = "#define L0 x\n";
    for (int i = 1; i <= 40; ++i)
        src += "#define L" + std::to_string(i) + " L" + std::to_string(i - 1) + " L" + std::to_string(i - 1) + "\n";
    src += "L40\nL40\n";
    Run r = pp(src);
    CHECK(r.diags.has("P1012"));
    CHECK(r.diags.errorCount() == 1);

    // Deeply nested arguments.
    std::string nested = "#define F(x) x\n";
    for (int i = 0; i < 1000; ++i) nested += "F(";
    nested += "1";
    for (int i = 0; i < 1000; ++i) nested += ")";
    CHECK(pp(nested + "\n").diags.has("P1012"));
}

TEST_CASE("preprocessor: P1014 malformed directive", "[preprocessor][diag]") {
    for (const char* src : {"#include\n", "#include foo\n", "#include \"x\n", "#include <>\n", "#ifdef\n#endif\n",
                            "#ifndef 3\n#endif\n", "#line\n"}) {
        INFO(src);
        CHECK(pp(src).diags.has("P1014"));
    }
    CHECK(pp("#ifdef\nx\n#endif\n").texts().empty());
}

TEST_CASE("preprocessor: P1015 extra tokens warning", "[preprocessor][diag]") {
    Run r = pp("#ifdef A B\n#else C\n#endif D\n#undef A B\n#include \"i\" junk\n", {}, {{"i", ""}});
    size_t warnings = 0;
    for (const Diagnostic& d : r.diags.all())
        if (d.code == "P1015" && d.severity == Severity::Warning) ++warnings;
    CHECK(warnings == 5);
    CHECK_FALSE(r.diags.hasErrors());
}

TEST_CASE("preprocessor: garbage input never crashes or hangs", "[preprocessor]") {
    std::string junk;
    uint32_t x = 12345;
    for (int i = 0; i < 20000; ++i) {
        x = x * 1103515245u + 12345u;
        static const char alphabet[] = "#defin(),;/*\\\n\r\"'<>AB x01?:|&!~_^%";
        junk += alphabet[(x >> 16) % (sizeof(alphabet) - 1)];
    }
    Run r = pp(junk);
    CHECK(r.lines.size() <= 20000);
    Run nul = pp(std::string("mov\0r0\n#define\0\n", 16));
    CHECK(nul.lines.size() == 1);
}
