// Internals of the preprocessor shared by its files: preprocessor.cpp (lines, directives,
// #include), preprocessor_macros.cpp (#define, #undef and macro expansion) and
// preprocessor_expr.cpp (#if expressions). Not part of the public interface.
#pragma once

#include <algorithm>
#include <climits>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ps11/diagnostics.h"
#include "ps11/preprocessor.h"

namespace ps11::preprocessor_detail {

inline constexpr uint32_t kNoSrc = UINT32_MAX;
inline constexpr int kMaxExpandDepth = 200;           // nesting of macro-argument pre-expansion
inline constexpr int kMaxExprDepth = 256;             // nesting of #if sub-expressions
inline constexpr int kHardIncludeDepth = 200;         // cap on options.maxIncludeDepth (C++ stack)
inline constexpr size_t kMaxIncludes = 4096;          // #include files opened per preprocess() call
inline constexpr int64_t kWorkBudget = 4 << 20;       // macro-expansion work units per preprocess() call
inline constexpr size_t kMaxSourceBytes = 64u << 20;  // bytes of included source per call

enum class TokKind : uint8_t { Ident, Number, Punct, Space, Other, Placemarker };

struct Token {
    TokKind kind = TokKind::Punct;
    std::string text;
    uint32_t src = kNoSrc;  // byte offset in the logical line when the token is unchanged source text
    uint32_t col = 0;       // original column (of the token, or of the macro name that produced it)
    uint32_t hs = 0;        // hide set id (HideSets)
};

inline bool isIdentStart(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
inline bool isDigit(char c) { return c >= '0' && c <= '9'; }
inline bool isIdentChar(char c) { return isIdentStart(c) || isDigit(c); }
inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r'; }

// Length of the token starting at s[i] and its kind. Quotes are ordinary characters.
std::pair<TokKind, size_t> lexOne(std::string_view s, size_t i);

// Splits s[begin, end) into tokens. With `cols`, tokens are source text (src = offset, col from
// cols); without, every token gets `fixedCol` and no src.
void tokenize(std::string_view s, size_t begin, size_t end, const std::vector<uint32_t>* cols, uint32_t fixedCol,
              std::vector<Token>& out);

inline size_t skipSpace(const std::vector<Token>& t, size_t i) {
    while (i < t.size() && t[i].kind == TokKind::Space) ++i;
    return i;
}

inline bool isPunct(const Token& t, std::string_view s) { return t.kind == TokKind::Punct && t.text == s; }

std::string trim(std::string_view s);

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

std::optional<std::string> readFromDisk(const std::string& path);

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

}  // namespace ps11::preprocessor_detail
