// Preprocessor stage: shader source text → PreprocessedLines for the lexer. Splices
// backslash-newlines, strips // and /* */ comments (column-preserving), expands object- and
// function-like macros (Prosser's hide-set algorithm, with # and ##), evaluates conditionals,
// follows #include and keeps a per-byte map back to the original file, line and column.
// Diagnostic codes P1001..P1015 are listed in docs/diagnostics.md.
#include "ps11/preprocessor.h"

#include <algorithm>
#include <climits>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <unordered_map>

namespace ps11 {

SourceLoc PreprocessedLine::locAt(size_t byteIndex) const {
    SourceLoc loc;
    loc.fileId = fileId;
    loc.line = line;
    if (byteIndex < columns.size())
        loc.col = columns[byteIndex];
    else if (!columns.empty())
        loc.col = columns.back() + 1;
    else
        loc.col = 1;
    return loc;
}

namespace {

constexpr uint32_t kNoSrc = UINT32_MAX;
constexpr int kMaxExpandDepth = 200;           // nesting of macro-argument pre-expansion
constexpr int kMaxExprDepth = 256;             // nesting of #if sub-expressions
constexpr int kHardIncludeDepth = 200;         // cap on options.maxIncludeDepth (C++ stack)
constexpr size_t kMaxIncludes = 4096;          // #include files opened per preprocess() call
constexpr int64_t kWorkBudget = 4 << 20;       // macro-expansion work units per preprocess() call
constexpr size_t kMaxSourceBytes = 64u << 20;  // bytes of included source per call

enum class TokKind : uint8_t { Ident, Number, Punct, Space, Other, Placemarker };

struct Token {
    TokKind kind = TokKind::Punct;
    std::string text;
    uint32_t src = kNoSrc;  // byte offset in the logical line when the token is unchanged source text
    uint32_t col = 0;       // original column (of the token, or of the macro name that produced it)
    uint32_t hs = 0;        // hide set id (HideSets)
};

bool isIdentStart(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isIdentChar(char c) { return isIdentStart(c) || isDigit(c); }
bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r'; }

// Length of the token starting at s[i] and its kind. Quotes are ordinary characters.
std::pair<TokKind, size_t> lexOne(std::string_view s, size_t i) {
    const char c = s[i];
    size_t j = i + 1;
    if (isSpace(c)) {
        while (j < s.size() && isSpace(s[j])) ++j;
        return {TokKind::Space, j - i};
    }
    if (isIdentStart(c)) {
        while (j < s.size() && isIdentChar(s[j])) ++j;
        return {TokKind::Ident, j - i};
    }
    if (isDigit(c) || (c == '.' && j < s.size() && isDigit(s[j]))) {
        while (j < s.size()) {
            const char d = s[j];
            if ((d == '+' || d == '-') && (s[j - 1] == 'e' || s[j - 1] == 'E' || s[j - 1] == 'p' || s[j - 1] == 'P'))
                ++j;
            else if (isIdentChar(d) || d == '.')
                ++j;
            else
                break;
        }
        return {TokKind::Number, j - i};
    }
    if (c == '.' && i + 2 < s.size() && s[i + 1] == '.' && s[i + 2] == '.') return {TokKind::Punct, 3};
    if (j < s.size()) {
        static constexpr std::string_view kPairs[] = {"##", "<<", ">>", "<=", ">=", "==", "!=", "&&", "||"};
        for (std::string_view p : kPairs)
            if (s[i] == p[0] && s[j] == p[1]) return {TokKind::Punct, 2};
    }
    return {TokKind::Punct, 1};
}

// Splits s[begin, end) into tokens. With `cols`, tokens are source text (src = offset, col from
// cols); without, every token gets `fixedCol` and no src.
void tokenize(std::string_view s, size_t begin, size_t end, const std::vector<uint32_t>* cols, uint32_t fixedCol,
              std::vector<Token>& out) {
    std::string_view view = s.substr(0, end);
    for (size_t i = begin; i < end;) {
        auto [kind, len] = lexOne(view, i);
        Token t;
        t.kind = kind;
        t.text.assign(view.substr(i, len));
        if (cols) {
            t.src = uint32_t(i);
            t.col = (*cols)[i];
        } else {
            t.col = fixedCol;
        }
        out.push_back(std::move(t));
        i += len;
    }
}

size_t skipSpace(const std::vector<Token>& t, size_t i) {
    while (i < t.size() && t[i].kind == TokKind::Space) ++i;
    return i;
}

bool isPunct(const Token& t, std::string_view s) { return t.kind == TokKind::Punct && t.text == s; }

// Token or user text shown in a message, shortened so binary garbage stays readable.
std::string shown(std::string_view s) {
    std::string out;
    for (char c : s.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
    if (s.size() > 40) out += "...";
    return out;
}

std::string trim(std::string_view s) {
    size_t b = 0, e = s.size();
    while (b < e && isSpace(s[b])) ++b;
    while (e > b && isSpace(s[e - 1])) --e;
    return std::string(s.substr(b, e - b));
}

// ---- Source lines -------------------------------------------------------------------------

// One logical line: physical lines joined by backslash-newline, comments replaced by spaces.
struct LogicalLine {
    std::string text;
    std::vector<uint32_t> cols;            // 1-based physical column of each byte of text
    uint32_t line = 0;                     // first physical line
    uint32_t nextLine = 0;                 // physical line that follows this logical line
    bool directive = false;                // first significant character is '#'
    size_t semicolon = std::string::npos;  // first ';' of a text line (assembly comment start)
};

// Reads logical lines. Comment state carries across lines; a /* comment that is still open at
// the end of a directive line continues the directive (as in C), while on text lines it keeps
// the line structure (the remaining comment lines come out blank).
class LineReader {
public:
    explicit LineReader(std::string_view src) : m_src(src) {}

    bool next(LogicalLine& ll) {
        if (m_pos >= m_src.size()) return false;
        ll.text.clear();
        ll.cols.clear();
        ll.line = m_line;
        ll.directive = false;
        ll.semicolon = std::string::npos;
        bool seenSignificant = false, lineComment = false, opaque = false;
        auto put = [&ll](char c, uint32_t col) {
            ll.text += c;
            ll.cols.push_back(col);
        };
        while (m_pos < m_src.size()) {
            const char c = m_src[m_pos];
            if (c == '\r' && (m_pos + 1 == m_src.size() || m_src[m_pos + 1] == '\n')) {
                ++m_pos;
                continue;
            }
            if (c == '\\') {
                size_t n = m_pos + 1;
                if (n < m_src.size() && m_src[n] == '\r') ++n;
                if (n < m_src.size() && m_src[n] == '\n') {
                    m_pos = n + 1;
                    ++m_line;
                    m_col = 1;
                    continue;
                }
            }
            if (c == '\n') {
                ++m_pos;
                ++m_line;
                m_col = 1;
                if (m_inBlock && ll.directive) {
                    put(' ', ll.cols.empty() ? 1 : ll.cols.back());
                    continue;
                }
                break;
            }
            const uint32_t col = m_col++;
            ++m_pos;
            if (m_inBlock) {
                put(' ', col);
                if (c == '*' && m_pos < m_src.size() && m_src[m_pos] == '/') {
                    put(' ', m_col++);
                    ++m_pos;
                    m_inBlock = false;
                }
                continue;
            }
            if (lineComment) {
                put(' ', col);
                continue;
            }
            if (opaque) {
                put(c, col);
                continue;
            }
            if (c == '/' && m_pos < m_src.size() && (m_src[m_pos] == '/' || m_src[m_pos] == '*')) {
                if (m_src[m_pos] == '/') {
                    lineComment = true;
                } else {
                    m_inBlock = true;
                    m_blockLine = m_line;
                    m_blockCol = col;
                }
                put(' ', col);
                put(' ', m_col++);
                ++m_pos;
                continue;
            }
            if (!seenSignificant && !isSpace(c)) {
                seenSignificant = true;
                ll.directive = c == '#';
            }
            if (c == ';' && !ll.directive) {
                opaque = true;
                ll.semicolon = ll.text.size();
            }
            put(c, col);
        }
        ll.nextLine = m_line;
        return true;
    }

    bool inComment() const { return m_inBlock; }
    uint32_t commentLine() const { return m_blockLine; }
    uint32_t commentCol() const { return m_blockCol; }

private:
    std::string_view m_src;
    size_t m_pos = 0;
    uint32_t m_line = 1;
    uint32_t m_col = 1;
    bool m_inBlock = false;
    uint32_t m_blockLine = 0;
    uint32_t m_blockCol = 0;
};

// ---- Hide sets ----------------------------------------------------------------------------

// Interned sets of macro-name ids (Prosser's algorithm); id 0 is the empty set. Reset per line.
class HideSets {
public:
    explicit HideSets(int64_t& work) : m_work(work) { reset(); }

    void reset() {
        m_index.clear();
        m_sets.clear();
        m_unions.clear();
        m_sets.push_back(&m_index.emplace(std::vector<uint32_t>{}, 0).first->first);
    }
    bool contains(uint32_t hs, uint32_t name) const {
        const std::vector<uint32_t>& s = *m_sets[hs];
        return std::binary_search(s.begin(), s.end(), name);
    }
    uint32_t single(uint32_t name) { return intern({name}); }
    uint32_t unite(uint32_t a, uint32_t b) {
        if (a == b || b == 0) return a;
        if (a == 0) return b;
        const uint64_t key = (uint64_t(a) << 32) | b;
        if (auto it = m_unions.find(key); it != m_unions.end()) return it->second;
        std::vector<uint32_t> r;
        std::set_union(m_sets[a]->begin(), m_sets[a]->end(), m_sets[b]->begin(), m_sets[b]->end(),
                       std::back_inserter(r));
        const uint32_t id = intern(std::move(r));
        m_unions.emplace(key, id);
        return id;
    }
    uint32_t intersect(uint32_t a, uint32_t b) {
        if (a == b) return a;
        if (a == 0 || b == 0) return 0;
        std::vector<uint32_t> r;
        std::set_intersection(m_sets[a]->begin(), m_sets[a]->end(), m_sets[b]->begin(), m_sets[b]->end(),
                              std::back_inserter(r));
        return intern(std::move(r));
    }

private:
    uint32_t intern(std::vector<uint32_t> s) {
        m_work += int64_t(s.size()) + 1;
        auto [it, added] = m_index.emplace(std::move(s), uint32_t(m_sets.size()));
        if (added) m_sets.push_back(&it->first);
        return it->second;
    }

    int64_t& m_work;
    std::map<std::vector<uint32_t>, uint32_t> m_index;
    std::vector<const std::vector<uint32_t>*> m_sets;
    std::unordered_map<uint64_t, uint32_t> m_unions;
};

// ---- Macros and files ---------------------------------------------------------------------

struct Macro {
    bool functionLike = false;
    bool variadic = false;  // last parameter is __VA_ARGS__
    std::vector<std::string> params;
    std::vector<Token> body;  // trimmed, whitespace runs as one " ", no spaces around ##
    uint32_t nameId = 0;
    SourceLoc loc;

    int paramIndex(const Token& t) const {
        if (!functionLike || t.kind != TokKind::Ident) return -1;
        for (size_t i = 0; i < params.size(); ++i)
            if (params[i] == t.text) return int(i);
        return -1;
    }
    bool sameAs(const Macro& o) const {
        if (functionLike != o.functionLike || variadic != o.variadic || params != o.params) return false;
        if (body.size() != o.body.size()) return false;
        for (size_t i = 0; i < body.size(); ++i)
            if (body[i].kind != o.body[i].kind || body[i].text != o.body[i].text) return false;
        return true;
    }
};

struct Conditional {
    SourceLoc loc;
    std::string directive;  // "#if", "#ifdef", "#ifndef"
    bool parentActive = true;
    bool taken = false;   // some branch of this group has been taken
    bool active = false;  // the current branch is being output
    bool seenElse = false;
};

struct FileCtx {
    std::string path;
    uint32_t fileId = 0;        // the file's own id (includes resolve against path)
    uint32_t reportFileId = 0;  // id used for output and diagnostics (#line may change it)
    int64_t lineDelta = 0;      // #line adjustment
    std::vector<Conditional> conds;
    bool active() const { return conds.empty() || conds.back().active; }
};

std::string dirOf(const std::string& path) {
    const size_t p = path.find_last_of("/\\");
    return p == std::string::npos ? std::string() : path.substr(0, p + 1);
}

bool isAbsolute(const std::string& p) {
    return !p.empty() && (p[0] == '/' || p[0] == '\\' || (p.size() >= 2 && p[1] == ':'));
}

// Lexically normalized path (for recursion and #pragma once checks only).
std::string normalizePath(const std::string& path) {
    std::vector<std::string> parts;
    const bool rooted = !path.empty() && (path[0] == '/' || path[0] == '\\');
    std::string cur;
    auto flush = [&]() {
        if (cur.empty() || cur == ".") {
        } else if (cur == ".." && !parts.empty() && parts.back() != "..") {
            parts.pop_back();
        } else {
            parts.push_back(cur);
        }
        cur.clear();
    };
    for (char c : path) {
        if (c == '/' || c == '\\')
            flush();
        else
            cur += c;
    }
    flush();
    std::string out = rooted ? "/" : "";
    for (size_t i = 0; i < parts.size(); ++i) out += (i ? "/" : "") + parts[i];
    return out;
}

std::optional<std::string> readFromDisk(const std::string& path) {
    std::error_code ec;
    if (path.empty() || !std::filesystem::is_regular_file(path, ec) || ec) return std::nullopt;
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Parses "name" or <name> at the start of s (after spaces). Returns false if malformed.
bool parseHeaderName(std::string_view s, std::string& name, size_t& end) {
    size_t i = 0;
    while (i < s.size() && isSpace(s[i])) ++i;
    if (i >= s.size() || (s[i] != '"' && s[i] != '<')) return false;
    const char close = s[i] == '"' ? '"' : '>';
    const size_t e = s.find(close, i + 1);
    if (e == std::string_view::npos || e == i + 1) return false;
    name.assign(s.substr(i + 1, e - i - 1));
    end = e + 1;
    return true;
}

// ---- The preprocessor ---------------------------------------------------------------------

class Preprocessor {
public:
    Preprocessor(const PreprocessOptions& options, Diagnostics& diags)
        : m_opts(options), m_diags(diags), m_hs(m_work) {}

    std::vector<PreprocessedLine> run(std::string_view source, const std::string& fileName);

private:
    // #if expression evaluator over fully expanded tokens.
    class Expr;

    void processFile(std::string_view src, const std::string& path, uint32_t fileId, int depth);
    void handleDirective(FileCtx& f, const LogicalLine& ll, int depth);
    void emitText(FileCtx& f, const LogicalLine& ll);
    void emitBlank(FileCtx& f, const LogicalLine& ll);

    void doDefine(const std::vector<Token>& toks, size_t i, uint32_t endCol);
    void doUndef(const std::vector<Token>& toks, size_t i, uint32_t endCol);
    bool evalCondition(const std::vector<Token>& toks, size_t i, uint32_t dirCol, uint32_t endCol);
    bool ifdefName(const std::vector<Token>& toks, size_t i, std::string_view dir, uint32_t endCol, bool& ok);
    void doInclude(FileCtx& f, const LogicalLine& ll, const std::vector<Token>& toks, size_t i, uint32_t dirCol,
                   int depth);
    void doLine(FileCtx& f, const LogicalLine& ll, const std::vector<Token>& toks, size_t i, uint32_t dirCol);
    void extraTokens(const std::vector<Token>& toks, size_t i, std::string_view dir);

    void expand(std::vector<Token> input, std::vector<Token>& out, int depth);
    std::vector<Token> substitute(const Macro& m, const std::vector<std::vector<Token>>& args, uint32_t hs,
                                  uint32_t col, int depth);
    void paste(std::vector<Token>& out, const std::vector<Token>& right, uint32_t col);
    bool charge(int64_t units);
    void limitError(uint32_t col, const std::string& what);

    uint32_t nameId(const std::string& name) {
        return m_nameIds.emplace(name, uint32_t(m_nameIds.size())).first->second;
    }
    SourceLoc at(uint32_t col) const { return SourceLoc{m_locFile, m_locLine, col, -1}; }
    uint32_t mapLine(const FileCtx& f, uint32_t line) const {
        return uint32_t(std::clamp<int64_t>(int64_t(line) + f.lineDelta, 0, UINT32_MAX));
    }
    std::optional<std::string> readFile(const std::string& path) const {
        return m_opts.readFile ? m_opts.readFile(path) : readFromDisk(path);
    }

    const PreprocessOptions& m_opts;
    Diagnostics& m_diags;
    std::vector<PreprocessedLine> m_out;
    std::unordered_map<std::string, Macro> m_macros;
    std::unordered_map<std::string, uint32_t> m_nameIds;
    int64_t m_work = 0;
    bool m_limitHit = false;
    bool m_inIf = false;  // expanding a #if/#elif line
    HideSets m_hs;
    std::vector<std::string> m_includeStack;  // normalized paths of the files being read
    std::set<std::string> m_onceFiles;        // #pragma once
    size_t m_includeCount = 0;
    size_t m_sourceBytes = 0;
    uint32_t m_locFile = 0;  // where diagnostics of the current line go
    uint32_t m_locLine = 0;
};

// Recursive-descent evaluator with C precedence; `eval` false marks operands that short-circuit
// away, where division by zero is not an error (as in C).
class Preprocessor::Expr {
public:
    Expr(Preprocessor& pp, const std::vector<Token>& toks, uint32_t endCol) : m_pp(pp), m_t(toks), m_endCol(endCol) {}

    std::optional<int64_t> run() {
        const int64_t v = ternary(true);
        if (!m_failed && m_i < m_t.size()) fail(m_t[m_i].col, "unexpected '" + shown(m_t[m_i].text) + "' in #if");
        if (m_failed) return std::nullopt;
        return v;
    }

private:
    struct Depth {
        explicit Depth(Expr& e) : m_e(e) { ++m_e.m_depth; }
        ~Depth() { --m_e.m_depth; }
        Expr& m_e;
    };

    void fail(uint32_t col, std::string msg) {
        if (m_failed) return;
        m_failed = true;
        m_pp.m_diags.error("P1006", m_pp.at(col), std::move(msg));
    }
    uint32_t curCol() const { return m_i < m_t.size() ? m_t[m_i].col : m_endCol; }
    bool accept(std::string_view s) {
        if (m_i < m_t.size() && isPunct(m_t[m_i], s)) {
            ++m_i;
            return true;
        }
        return false;
    }
    bool tooDeep() {
        if (m_depth <= kMaxExprDepth) return false;
        fail(curCol(), "#if expression nested too deeply (limit " + std::to_string(kMaxExprDepth) + ")");
        return true;
    }

    int64_t ternary(bool eval) {
        Depth d(*this);
        if (tooDeep()) return 0;
        const int64_t c = binary(1, eval);
        if (m_failed || !accept("?")) return c;
        const int64_t a = ternary(eval && c != 0);
        if (!accept(":")) {
            fail(curCol(), "expected ':' in '?:' expression in #if");
            return 0;
        }
        const int64_t b = ternary(eval && c == 0);
        return c ? a : b;
    }

    static int precedence(const Token& t) {
        if (t.kind != TokKind::Punct) return -1;
        static const std::pair<std::string_view, int> kOps[] = {
            {"||", 1}, {"&&", 2}, {"|", 3},  {"^", 4},  {"&", 5}, {"==", 6}, {"!=", 6}, {"<", 7},  {"<=", 7},
            {">", 7},  {">=", 7}, {"<<", 8}, {">>", 8}, {"+", 9}, {"-", 9},  {"*", 10}, {"/", 10}, {"%", 10}};
        for (const auto& [op, p] : kOps)
            if (t.text == op) return p;
        return -1;
    }

    int64_t binary(int minPrec, bool eval) {
        int64_t lhs = unary(eval);
        while (!m_failed && m_i < m_t.size()) {
            const int prec = precedence(m_t[m_i]);
            if (prec < minPrec) break;
            const std::string op = m_t[m_i].text;
            const uint32_t col = m_t[m_i].col;
            ++m_i;
            bool evalRhs = eval;
            if (op == "||") evalRhs = eval && lhs == 0;
            if (op == "&&") evalRhs = eval && lhs != 0;
            const int64_t rhs = binary(prec + 1, evalRhs);
            if (m_failed) return 0;
            lhs = apply(op, lhs, rhs, eval, col);
        }
        return lhs;
    }

    int64_t apply(const std::string& op, int64_t a, int64_t b, bool eval, uint32_t col) {
        const uint64_t ua = uint64_t(a), ub = uint64_t(b);
        if (op == "+") return int64_t(ua + ub);
        if (op == "-") return int64_t(ua - ub);
        if (op == "*") return int64_t(ua * ub);
        if (op == "/" || op == "%") {
            if (b == 0) {
                if (eval) fail(col, std::string("division by zero in #if ('") + op + "' by 0)");
                return 0;
            }
            if (a == INT64_MIN && b == -1) return op == "/" ? a : 0;  // would overflow
            return op == "/" ? a / b : a % b;
        }
        // Shift counts outside 0..63 are undefined in C; here << gives 0 and >> gives the sign.
        if (op == "<<") return (b < 0 || b > 63) ? 0 : int64_t(ua << b);
        if (op == ">>") return b < 0 ? 0 : b > 63 ? (a < 0 ? -1 : 0) : (a >> b);
        if (op == "<") return a < b;
        if (op == "<=") return a <= b;
        if (op == ">") return a > b;
        if (op == ">=") return a >= b;
        if (op == "==") return a == b;
        if (op == "!=") return a != b;
        if (op == "&") return a & b;
        if (op == "^") return a ^ b;
        if (op == "|") return a | b;
        if (op == "&&") return a && b;
        return a || b;
    }

    int64_t unary(bool eval) {
        Depth d(*this);
        if (tooDeep()) return 0;
        if (m_i >= m_t.size()) {
            fail(m_endCol, "expected a value at the end of the #if expression");
            return 0;
        }
        const Token& t = m_t[m_i];
        if (t.kind == TokKind::Punct) {
            const std::string op = t.text;
            if (op == "+" || op == "-" || op == "~" || op == "!") {
                ++m_i;
                const int64_t v = unary(eval);
                if (op == "-") return int64_t(0 - uint64_t(v));
                if (op == "~") return ~v;
                if (op == "!") return !v;
                return v;
            }
            if (op == "(") {
                ++m_i;
                const int64_t v = ternary(eval);
                if (!m_failed && !accept(")")) fail(curCol(), "missing ')' in #if expression");
                return v;
            }
        }
        ++m_i;
        if (t.kind == TokKind::Number) return number(t);
        if (t.kind == TokKind::Ident) {
            if (t.text != "defined") return 0;  // unknown identifiers are 0, as in C
            // 'defined' produced by a macro expansion.
            const bool paren = accept("(");
            if (m_i >= m_t.size() || m_t[m_i].kind != TokKind::Ident) {
                fail(curCol(), "'defined' must be followed by a macro name");
                return 0;
            }
            const bool def = m_pp.m_macros.count(m_t[m_i++].text) != 0;
            if (paren && !accept(")")) fail(curCol(), "missing ')' after 'defined(NAME'");
            return def;
        }
        fail(t.col, "unexpected '" + shown(t.text) + "' in #if expression");
        return 0;
    }

    int64_t number(const Token& t) {
        std::string_view s = t.text;
        while (!s.empty() && (s.back() == 'u' || s.back() == 'U' || s.back() == 'l' || s.back() == 'L'))
            s.remove_suffix(1);
        uint64_t v = 0;
        size_t i = 0;
        unsigned base = 10;
        if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
            base = 16;
            i = 2;
        } else if (s.size() > 1 && s[0] == '0') {
            base = 8;
            i = 1;
        }
        bool ok = i < s.size() || base == 8;
        for (; ok && i < s.size(); ++i) {
            const char c = s[i];
            unsigned d = 99;
            if (isDigit(c))
                d = unsigned(c - '0');
            else if (c >= 'a' && c <= 'f')
                d = unsigned(c - 'a' + 10);
            else if (c >= 'A' && c <= 'F')
                d = unsigned(c - 'A' + 10);
            if (d >= base)
                ok = false;
            else
                v = v * base + d;  // wraps on overflow, like an unsigned C constant
        }
        if (!ok) {
            fail(t.col, "invalid integer constant '" + shown(t.text) + "' in #if (only integers are allowed)");
            return 0;
        }
        return int64_t(v);
    }

    Preprocessor& m_pp;
    const std::vector<Token>& m_t;
    uint32_t m_endCol;
    size_t m_i = 0;
    int m_depth = 0;
    bool m_failed = false;
};

std::vector<PreprocessedLine> Preprocessor::run(std::string_view source, const std::string& fileName) {
    m_locFile = m_diags.addFile("<command line>");
    m_locLine = 0;
    for (const auto& [name, value] : m_opts.defines) {
        std::string text = name + " " + value;
        std::replace(text.begin(), text.end(), '\n', ' ');
        std::vector<Token> toks;
        tokenize(text, 0, text.size(), nullptr, 0, toks);
        doDefine(toks, 0, 0);
    }
    const uint32_t fileId = m_diags.addFile(fileName);
    m_sourceBytes = source.size();
    processFile(source, fileName, fileId, 0);
    return std::move(m_out);
}

void Preprocessor::processFile(std::string_view src, const std::string& path, uint32_t fileId, int depth) {
    if (src.substr(0, 3) == "\xEF\xBB\xBF") src.remove_prefix(3);  // UTF-8 byte order mark
    FileCtx f;
    f.path = path;
    f.fileId = f.reportFileId = fileId;
    m_includeStack.push_back(normalizePath(path));
    LineReader reader(src);
    LogicalLine ll;
    while (reader.next(ll)) {
        m_hs.reset();
        m_locFile = f.reportFileId;
        m_locLine = mapLine(f, ll.line);
        if (ll.directive)
            handleDirective(f, ll, depth);
        else if (f.active())
            emitText(f, ll);
        else
            emitBlank(f, ll);
    }
    if (reader.inComment())
        m_diags.error("P1010", SourceLoc{f.reportFileId, mapLine(f, reader.commentLine()), reader.commentCol(), -1},
                      "unterminated /* comment (no closing */ before the end of the file)");
    for (const Conditional& c : f.conds)
        m_diags.error("P1001", c.loc, "unterminated " + c.directive + " (no matching #endif in this file)");
    m_includeStack.pop_back();
}

void Preprocessor::emitBlank(FileCtx& f, const LogicalLine& ll) {
    PreprocessedLine out;
    out.fileId = f.reportFileId;
    out.line = mapLine(f, ll.line);
    m_out.push_back(std::move(out));
}

void Preprocessor::emitText(FileCtx& f, const LogicalLine& ll) {
    PreprocessedLine out;
    out.fileId = f.reportFileId;
    out.line = mapLine(f, ll.line);
    const size_t cut = std::min(ll.semicolon, ll.text.size());
    if (m_macros.empty()) {
        out.text = ll.text;
        out.columns = ll.cols;
    } else {
        std::vector<Token> toks, expanded;
        tokenize(ll.text, 0, cut, &ll.cols, 0, toks);
        expand(std::move(toks), expanded, 0);
        for (const Token& t : expanded) {
            out.text += t.text;
            for (size_t k = 0; k < t.text.size(); ++k)
                out.columns.push_back(t.src != kNoSrc && t.src + k < ll.cols.size() ? ll.cols[t.src + k] : t.col);
        }
        out.text.append(ll.text, cut, std::string::npos);
        out.columns.insert(out.columns.end(), ll.cols.begin() + std::ptrdiff_t(cut), ll.cols.end());
    }
    m_out.push_back(std::move(out));
}

void Preprocessor::handleDirective(FileCtx& f, const LogicalLine& ll, int depth) {
    size_t hash = 0;
    while (hash < ll.text.size() && ll.text[hash] != '#') ++hash;
    const uint32_t dirCol = hash < ll.cols.size() ? ll.cols[hash] : 1;
    const uint32_t endCol = ll.cols.empty() ? 1 : ll.cols.back() + 1;
    std::vector<Token> toks;
    tokenize(ll.text, hash + 1, ll.text.size(), &ll.cols, 0, toks);
    size_t i = skipSpace(toks, 0);
    if (i >= toks.size()) return;  // the null directive '#'
    const bool active = f.active();
    if (toks[i].kind != TokKind::Ident) {
        if (active)
            m_diags.error("P1008", at(toks[i].col), "invalid preprocessor directive '#" + shown(toks[i].text) + "'");
        return;
    }
    const std::string name = toks[i].text;
    const uint32_t nameCol = toks[i].col;
    ++i;

    if (name == "if" || name == "ifdef" || name == "ifndef") {
        Conditional c;
        c.loc = at(dirCol);
        c.directive = "#" + name;
        c.parentActive = active;
        if (!active) {
            c.taken = true;  // no branch of a group inside skipped text is ever output
        } else if (name == "if") {
            c.taken = c.active = evalCondition(toks, i, dirCol, endCol);
        } else {
            bool ok = true;
            const bool def = ifdefName(toks, i, name, endCol, ok);
            c.taken = c.active = ok && (name == "ifdef" ? def : !def);
        }
        f.conds.push_back(std::move(c));
        return;
    }
    if (name == "elif" || name == "else" || name == "endif") {
        if (f.conds.empty()) {
            m_diags.error("P1002", at(dirCol), "#" + name + " without a matching #if");
            return;
        }
        Conditional& c = f.conds.back();
        if (name == "endif") {
            if (c.parentActive) extraTokens(toks, i, "#endif");
            f.conds.pop_back();
            return;
        }
        if (c.seenElse) {
            m_diags.error("P1002", at(dirCol),
                          "#" + name + " after #else in the " + c.directive + " group opened at line " +
                              std::to_string(c.loc.line));
            c.active = false;
            return;
        }
        if (name == "else") {
            if (c.parentActive) extraTokens(toks, i, "#else");
            c.seenElse = true;
            c.active = c.parentActive && !c.taken;
            c.taken = true;
            return;
        }
        if (!c.parentActive || c.taken) {
            c.active = false;  // not evaluated, as in C
        } else {
            c.taken = c.active = evalCondition(toks, i, dirCol, endCol);
        }
        return;
    }
    if (!active) return;  // other directives in skipped text are ignored, even unknown ones

    if (name == "define") {
        doDefine(toks, i, endCol);
    } else if (name == "undef") {
        doUndef(toks, i, endCol);
    } else if (name == "include") {
        doInclude(f, ll, toks, i, dirCol, depth);
    } else if (name == "error") {
        const size_t from = i < toks.size() ? toks[i].src : ll.text.size();
        m_diags.error("P1007", at(dirCol), "#error " + trim(std::string_view(ll.text).substr(from)));
    } else if (name == "pragma") {
        const size_t j = skipSpace(toks, i);
        if (j < toks.size() && toks[j].text == "once") m_onceFiles.insert(normalizePath(f.path));
    } else if (name == "line") {
        doLine(f, ll, toks, i, dirCol);
    } else {
        m_diags.error("P1008", at(nameCol), "unknown preprocessor directive '#" + shown(name) + "'");
    }
}

void Preprocessor::extraTokens(const std::vector<Token>& toks, size_t i, std::string_view dir) {
    i = skipSpace(toks, i);
    if (i < toks.size())
        m_diags.warning("P1015", at(toks[i].col),
                        "extra tokens after " + std::string(dir) + " ignored ('" + shown(toks[i].text) + "')");
}

void Preprocessor::doDefine(const std::vector<Token>& toks, size_t i, uint32_t endCol) {
    i = skipSpace(toks, i);
    if (i >= toks.size() || toks[i].kind != TokKind::Ident) {
        if (i >= toks.size())
            m_diags.error("P1005", at(endCol), "#define needs a macro name");
        else
            m_diags.error("P1005", at(toks[i].col),
                          "macro name must be an identifier, not '" + shown(toks[i].text) + "'");
        return;
    }
    const Token& nameTok = toks[i];
    if (nameTok.text == "defined") {
        m_diags.error("P1005", at(nameTok.col), "'defined' cannot be used as a macro name");
        return;
    }
    Macro m;
    m.loc = at(nameTok.col);
    ++i;
    if (i < toks.size() && isPunct(toks[i], "(")) {
        m.functionLike = true;
        ++i;
        for (bool first = true;; first = false) {
            i = skipSpace(toks, i);
            if (i >= toks.size()) {
                m_diags.error("P1005", at(endCol), "missing ')' in the parameter list of macro '" + nameTok.text + "'");
                return;
            }
            const Token& t = toks[i];
            if (first && isPunct(t, ")")) {
                ++i;
                break;
            }
            if (t.kind == TokKind::Ident) {
                if (t.text == "__VA_ARGS__" || std::find(m.params.begin(), m.params.end(), t.text) != m.params.end()) {
                    m_diags.error("P1005", at(t.col), "duplicate or reserved macro parameter '" + t.text + "'");
                    return;
                }
                m.params.push_back(t.text);
            } else if (isPunct(t, "...")) {
                m.variadic = true;
                m.params.push_back("__VA_ARGS__");
            } else {
                m_diags.error(
                    "P1005", at(t.col),
                    "expected a parameter name in macro '" + nameTok.text + "', found '" + shown(t.text) + "'");
                return;
            }
            i = skipSpace(toks, i + 1);
            if (i < toks.size() && isPunct(toks[i], ")")) {
                ++i;
                break;
            }
            if (i < toks.size() && isPunct(toks[i], ",") && !m.variadic) {
                ++i;
                continue;
            }
            m_diags.error("P1005", at(i < toks.size() ? toks[i].col : endCol),
                          m.variadic ? "'...' must be the last parameter of macro '" + nameTok.text + "'"
                                     : "expected ',' or ')' in the parameter list of macro '" + nameTok.text + "'");
            return;
        }
    }
    // Body: trimmed, whitespace runs collapsed, no whitespace around ##.
    for (; i < toks.size(); ++i) {
        Token t = toks[i];
        t.src = kNoSrc;
        if (t.kind == TokKind::Space) {
            if (m.body.empty() || m.body.back().kind == TokKind::Space || isPunct(m.body.back(), "##")) continue;
            t.text = " ";
        } else if (isPunct(t, "##") && !m.body.empty() && m.body.back().kind == TokKind::Space) {
            m.body.pop_back();
        }
        m.body.push_back(std::move(t));
    }
    if (!m.body.empty() && m.body.back().kind == TokKind::Space) m.body.pop_back();
    if (!m.body.empty() && (isPunct(m.body.front(), "##") || isPunct(m.body.back(), "##"))) {
        const Token& bad = isPunct(m.body.front(), "##") ? m.body.front() : m.body.back();
        m_diags.error("P1005", at(bad.col),
                      "'##' cannot appear at either end of the body of macro '" + nameTok.text + "'");
        return;
    }
    if (m.functionLike) {
        for (size_t k = 0; k < m.body.size(); ++k) {
            if (!isPunct(m.body[k], "#")) continue;
            size_t n = k + 1;
            if (n < m.body.size() && m.body[n].kind == TokKind::Space) ++n;
            if (n >= m.body.size() || m.paramIndex(m.body[n]) < 0) {
                m_diags.error("P1005", at(m.body[k].col),
                              "'#' is not followed by a parameter in the body of macro '" + nameTok.text + "'");
                return;
            }
        }
    }
    m.nameId = nameId(nameTok.text);
    auto it = m_macros.find(nameTok.text);
    if (it != m_macros.end()) {
        if (!it->second.sameAs(m)) {
            m_diags.warning("P1013", m.loc, "macro '" + nameTok.text + "' redefined with a different body");
            m_diags.note(it->second.loc, "previous definition of '" + nameTok.text + "' is here");
        }
        it->second = std::move(m);
    } else {
        m_macros.emplace(nameTok.text, std::move(m));
    }
}

void Preprocessor::doUndef(const std::vector<Token>& toks, size_t i, uint32_t endCol) {
    i = skipSpace(toks, i);
    if (i >= toks.size() || toks[i].kind != TokKind::Ident) {
        m_diags.error("P1005", at(i < toks.size() ? toks[i].col : endCol), "#undef needs a macro name");
        return;
    }
    m_macros.erase(toks[i].text);
    extraTokens(toks, i + 1, "#undef");
}

bool Preprocessor::ifdefName(const std::vector<Token>& toks, size_t i, std::string_view dir, uint32_t endCol,
                             bool& ok) {
    i = skipSpace(toks, i);
    if (i >= toks.size() || toks[i].kind != TokKind::Ident) {
        m_diags.error("P1014", at(i < toks.size() ? toks[i].col : endCol),
                      "#" + std::string(dir) + " needs a macro name");
        ok = false;
        return false;
    }
    extraTokens(toks, i + 1, "#" + std::string(dir));
    return m_macros.count(toks[i].text) != 0;
}

bool Preprocessor::evalCondition(const std::vector<Token>& toks, size_t i, uint32_t dirCol, uint32_t endCol) {
    // 'defined NAME' / 'defined(NAME)' are replaced before expansion so NAME is not expanded.
    std::vector<Token> pre;
    for (; i < toks.size(); ++i) {
        if (toks[i].kind != TokKind::Ident || toks[i].text != "defined") {
            pre.push_back(toks[i]);
            continue;
        }
        size_t j = skipSpace(toks, i + 1);
        const bool paren = j < toks.size() && isPunct(toks[j], "(");
        if (paren) j = skipSpace(toks, j + 1);
        if (j >= toks.size() || toks[j].kind != TokKind::Ident) {
            m_diags.error("P1006", at(j < toks.size() ? toks[j].col : endCol),
                          "'defined' must be followed by a macro name");
            return false;
        }
        const bool def = m_macros.count(toks[j].text) != 0;
        if (paren) {
            j = skipSpace(toks, j + 1);
            if (j >= toks.size() || !isPunct(toks[j], ")")) {
                m_diags.error("P1006", at(j < toks.size() ? toks[j].col : endCol), "missing ')' after 'defined(NAME'");
                return false;
            }
        }
        Token v;
        v.kind = TokKind::Number;
        v.text = def ? "1" : "0";
        v.col = toks[i].col;
        pre.push_back(std::move(v));
        i = j;
    }
    std::vector<Token> expanded;
    m_inIf = true;
    expand(std::move(pre), expanded, 0);
    m_inIf = false;
    expanded.erase(
        std::remove_if(expanded.begin(), expanded.end(), [](const Token& t) { return t.kind == TokKind::Space; }),
        expanded.end());
    if (expanded.empty()) {
        m_diags.error("P1006", at(dirCol), "#if/#elif with no expression");
        return false;
    }
    Expr e(*this, expanded, endCol);
    const std::optional<int64_t> v = e.run();
    return v && *v != 0;
}

void Preprocessor::doInclude(FileCtx& f, const LogicalLine& ll, const std::vector<Token>& toks, size_t i,
                             uint32_t dirCol, int depth) {
    i = skipSpace(toks, i);
    std::string name, rest;
    size_t end = 0;
    uint32_t nameCol = i < toks.size() ? toks[i].col : dirCol;
    bool ok = i < toks.size() && parseHeaderName(std::string_view(ll.text).substr(toks[i].src), name, end);
    if (ok) {
        rest = ll.text.substr(toks[i].src + end);
    } else if (i < toks.size()) {
        // #include MACRO: expand, then expect "file" or <file>.
        std::vector<Token> expanded;
        expand(std::vector<Token>(toks.begin() + std::ptrdiff_t(i), toks.end()), expanded, 0);
        std::string text;
        for (const Token& t : expanded) text += t.text;
        ok = parseHeaderName(text, name, end);
        if (ok) rest = text.substr(end);
    }
    if (!ok) {
        m_diags.error("P1014", at(nameCol), "#include expects \"FILE\" or <FILE>");
        return;
    }
    if (!trim(rest).empty())
        m_diags.warning("P1015", at(nameCol), "extra tokens after #include ignored ('" + shown(trim(rest)) + "')");

    const int maxDepth = std::min(m_opts.maxIncludeDepth, kHardIncludeDepth);
    if (depth + 1 > maxDepth) {
        m_diags.error(
            "P1004", at(nameCol),
            "#include nested too deeply (limit " + std::to_string(maxDepth) + ") including '" + shown(name) + "'");
        return;
    }
    std::vector<std::string> candidates;
    if (isAbsolute(name)) {
        candidates.push_back(name);
    } else {
        candidates.push_back(dirOf(f.path) + name);
        for (const std::string& d : m_opts.includeDirs) {
            if (d.empty() || d.back() == '/' || d.back() == '\\')
                candidates.push_back(d + name);
            else
                candidates.push_back(d + "/" + name);
        }
    }
    std::optional<std::string> content;
    std::string found;
    for (const std::string& c : candidates) {
        content = readFile(c);
        if (content) {
            found = c;
            break;
        }
    }
    if (!content) {
        std::string searched;
        for (const std::string& c : candidates) searched += (searched.empty() ? "" : ", ") + shown(c);
        m_diags.error("P1003", at(nameCol), "cannot open include file '" + shown(name) + "' (tried " + searched + ")");
        return;
    }
    const std::string key = normalizePath(found);
    if (m_onceFiles.count(key)) return;
    if (std::find(m_includeStack.begin(), m_includeStack.end(), key) != m_includeStack.end()) {
        m_diags.error("P1004", at(nameCol), "recursive #include of '" + shown(found) + "'");
        return;
    }
    if (m_includeCount >= kMaxIncludes) {
        m_diags.error("P1004", at(nameCol), "too many #include files (limit " + std::to_string(kMaxIncludes) + ")");
        return;
    }
    if (m_sourceBytes + content->size() > kMaxSourceBytes) {
        limitError(nameCol, "included source exceeds " + std::to_string(kMaxSourceBytes >> 20) + " MiB");
        return;
    }
    ++m_includeCount;
    m_sourceBytes += content->size();
    processFile(*content, found, m_diags.addFile(found), depth + 1);
}

void Preprocessor::doLine(FileCtx& f, const LogicalLine& ll, const std::vector<Token>& toks, size_t i,
                          uint32_t dirCol) {
    i = skipSpace(toks, i);
    const bool digits = i < toks.size() && toks[i].kind == TokKind::Number &&
                        std::all_of(toks[i].text.begin(), toks[i].text.end(), isDigit) && toks[i].text.size() <= 10;
    const int64_t n = digits ? std::stoll(toks[i].text) : -1;
    if (!digits || n > int64_t(UINT32_MAX)) {
        m_diags.error("P1014", at(i < toks.size() ? toks[i].col : dirCol), "#line expects a line number");
        return;
    }
    std::string name;
    size_t end = 0;
    const size_t j = skipSpace(toks, i + 1);
    if (j < toks.size()) {
        if (toks[j].text != "\"" || !parseHeaderName(std::string_view(ll.text).substr(toks[j].src), name, end)) {
            m_diags.error("P1014", at(toks[j].col), "#line expects a line number and an optional \"file name\"");
            return;
        }
        f.reportFileId = m_diags.addFile(name);
    }
    f.lineDelta = n - int64_t(ll.nextLine);
}

// ---- Macro expansion ----------------------------------------------------------------------

bool Preprocessor::charge(int64_t units) {
    m_work += units;
    if (m_work <= kWorkBudget) return true;
    limitError(0, "macro expansion is too large (more than " + std::to_string(kWorkBudget) + " work units)");
    return false;
}

void Preprocessor::limitError(uint32_t col, const std::string& what) {
    if (m_limitHit) return;
    m_limitHit = true;
    m_diags.error("P1012", at(col), what + "; further macro expansion and includes are disabled");
}

// Prosser's algorithm: a macro name is not expanded if it is in its token's hide set, and each
// replacement token's hide set gains the macro (and for function-like macros the hide set of
// the closing parenthesis), so self-references stop while rescanning still sees the rest of
// the line.
void Preprocessor::expand(std::vector<Token> input, std::vector<Token>& out, int depth) {
    if (depth > kMaxExpandDepth) {
        limitError(input.empty() ? 0 : input.front().col,
                   "macro arguments nested too deeply (limit " + std::to_string(kMaxExpandDepth) + ")");
    }
    std::vector<Token> stack(std::make_move_iterator(input.rbegin()), std::make_move_iterator(input.rend()));
    while (!stack.empty()) {
        Token t = std::move(stack.back());
        stack.pop_back();
        if (t.kind != TokKind::Ident || m_limitHit) {
            out.push_back(std::move(t));
            continue;
        }
        if (m_inIf && t.text == "defined") {
            // 'defined NAME' produced by a macro inside #if: NAME is not expanded.
            out.push_back(std::move(t));
            while (!stack.empty()) {
                Token n = std::move(stack.back());
                stack.pop_back();
                const bool more = n.kind == TokKind::Space || isPunct(n, "(");
                out.push_back(std::move(n));
                if (!more) break;
            }
            continue;
        }
        auto it = m_macros.find(t.text);
        if (it == m_macros.end() || m_hs.contains(t.hs, it->second.nameId)) {
            out.push_back(std::move(t));
            continue;
        }
        const Macro& m = it->second;
        std::vector<Token> repl;
        if (!m.functionLike) {
            repl = substitute(m, {}, m_hs.unite(t.hs, m_hs.single(m.nameId)), t.col, depth);
        } else {
            size_t open = stack.size();
            while (open > 0 && stack[open - 1].kind == TokKind::Space) --open;
            if (open == 0 || !isPunct(stack[open - 1], "(")) {
                out.push_back(std::move(t));  // a function-like name without '(' is not a call
                continue;
            }
            // Arguments: stack[open - 2] down to the matching ')'.
            const size_t np = m.params.size();
            std::vector<std::vector<Token>> args(1);
            int nest = 0;
            size_t close = SIZE_MAX;
            for (size_t k = open - 1; k-- > 0;) {
                Token& a = stack[k];
                if (isPunct(a, "(")) {
                    ++nest;
                } else if (isPunct(a, ")")) {
                    if (nest == 0) {
                        close = k;
                        break;
                    }
                    --nest;
                } else if (isPunct(a, ",") && nest == 0 && !(m.variadic && args.size() >= np)) {
                    args.emplace_back();
                    continue;
                }
                args.back().push_back(a);
            }
            if (close == SIZE_MAX) {
                m_diags.error("P1011", at(t.col), "unterminated argument list invoking macro '" + t.text + "'");
                out.push_back(std::move(t));
                continue;
            }
            const uint32_t closeHs = stack[close].hs;
            stack.resize(close);
            for (std::vector<Token>& a : args) {
                while (!a.empty() && a.back().kind == TokKind::Space) a.pop_back();
                a.erase(a.begin(),
                        std::find_if(a.begin(), a.end(), [](const Token& x) { return x.kind != TokKind::Space; }));
            }
            if (np == 0 && args.size() == 1 && args[0].empty()) args.clear();
            if (m.variadic && args.size() + 1 == np) args.emplace_back();
            if (args.size() != np) {
                m_diags.error("P1009", at(t.col),
                              "macro '" + t.text + "' expects " + std::to_string(np) + (m.variadic ? " or more" : "") +
                                  " argument" + (np == 1 ? "" : "s") + ", got " + std::to_string(args.size()));
                continue;
            }
            const uint32_t hs = m_hs.unite(m_hs.intersect(t.hs, closeHs), m_hs.single(m.nameId));
            repl = substitute(m, args, hs, t.col, depth);
        }
        if (m_limitHit) continue;
        for (auto r = repl.rbegin(); r != repl.rend(); ++r) stack.push_back(std::move(*r));
    }
}

std::vector<Token> Preprocessor::substitute(const Macro& m, const std::vector<std::vector<Token>>& args, uint32_t hs,
                                            uint32_t col, int depth) {
    std::vector<Token> out;
    std::vector<std::unique_ptr<std::vector<Token>>> expandedArgs(args.size());
    const std::vector<Token>& b = m.body;
    auto append = [&](const std::vector<Token>& ts) {
        int64_t cost = 0;
        for (const Token& x : ts) cost += int64_t(x.text.size()) + 8;
        if (!charge(cost)) return false;
        out.insert(out.end(), ts.begin(), ts.end());
        return true;
    };
    for (size_t i = 0; i < b.size() && !m_limitHit; ++i) {
        const Token& bt = b[i];
        if (m.functionLike && isPunct(bt, "#")) {
            size_t n = i + 1;
            if (n < b.size() && b[n].kind == TokKind::Space) ++n;
            const int p = n < b.size() ? m.paramIndex(b[n]) : -1;
            if (p >= 0) {  // checked by doDefine
                Token s;
                s.kind = TokKind::Other;
                s.col = col;
                s.text = "\"";
                for (const Token& a : args[size_t(p)]) {
                    if (a.kind == TokKind::Space) {
                        s.text += ' ';
                        continue;
                    }
                    for (char c : a.text) {
                        if (c == '"' || c == '\\') s.text += '\\';
                        s.text += c;
                    }
                }
                s.text += '"';
                if (!append({s})) break;
                i = n;
                continue;
            }
        }
        if (isPunct(bt, "##") && i + 1 < b.size()) {
            ++i;
            const int p = m.paramIndex(b[i]);
            std::vector<Token> right;
            if (p >= 0) {
                right = args[size_t(p)];
            } else {
                right.push_back(b[i]);
                right.back().col = col;
            }
            if (!charge(int64_t(right.size()) * 8)) break;
            paste(out, right, col);
            continue;
        }
        const int p = m.paramIndex(bt);
        if (p >= 0) {
            const std::vector<Token>& raw = args[size_t(p)];
            if (i + 1 < b.size() && isPunct(b[i + 1], "##")) {  // operand of ##: not expanded
                if (raw.empty()) {
                    Token pm;
                    pm.kind = TokKind::Placemarker;
                    out.push_back(std::move(pm));
                } else if (!append(raw)) {
                    break;
                }
                continue;
            }
            if (!expandedArgs[size_t(p)]) {
                expandedArgs[size_t(p)] = std::make_unique<std::vector<Token>>();
                expand(raw, *expandedArgs[size_t(p)], depth + 1);
            }
            if (!append(*expandedArgs[size_t(p)])) break;
            continue;
        }
        Token nt = bt;
        nt.col = col;
        if (!append({nt})) break;
    }
    if (m_limitHit) return {};
    out.erase(std::remove_if(out.begin(), out.end(), [](const Token& t) { return t.kind == TokKind::Placemarker; }),
              out.end());
    for (Token& t : out) t.hs = m_hs.unite(t.hs, hs);
    return out;
}

// a ## b: the last token of `out` and the first of `right` become one token (re-lexed); an
// empty operand (placemarker) leaves the other one unchanged.
void Preprocessor::paste(std::vector<Token>& out, const std::vector<Token>& right, uint32_t col) {
    if (right.empty()) return;
    if (out.empty() || out.back().kind == TokKind::Placemarker) {
        if (!out.empty()) out.pop_back();
        out.insert(out.end(), right.begin(), right.end());
        return;
    }
    const std::string joined = out.back().text + right.front().text;
    out.pop_back();
    tokenize(joined, 0, joined.size(), nullptr, col, out);
    out.insert(out.end(), right.begin() + 1, right.end());
}

}  // namespace

std::vector<PreprocessedLine> preprocess(std::string_view source, const std::string& fileName,
                                         const PreprocessOptions& options, Diagnostics& diags) {
    Preprocessor pp(options, diags);
    return pp.run(source, fileName);
}

}  // namespace ps11
