// Preprocessor stage: shader source text → PreprocessedLines for the lexer. This file splices
// backslash-newlines, strips // and /* */ comments (column-preserving), runs the directives and
// conditionals, follows #include and keeps a per-byte map back to file, line and column; macros
// are in preprocessor_macros.cpp, #if expressions in preprocessor_expr.cpp. Diagnostic codes
// P1001..P1015 are listed in docs/diagnostics.md.
#include "ps11/preprocessor.h"

#include <algorithm>
#include <climits>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include "ps11/preprocessor_internal.h"

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

namespace preprocessor_detail {

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

std::string trim(std::string_view s) {
    size_t b = 0, e = s.size();
    while (b < e && isSpace(s[b])) ++b;
    while (e > b && isSpace(s[e - 1])) --e;
    return std::string(s.substr(b, e - b));
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

namespace {

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

}  // namespace

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
            m_diags.error("P1008", at(toks[i].col), "invalid preprocessor directive '#" + excerpt(toks[i].text) + "'");
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
        m_diags.error("P1007", at(dirCol), "#error " + excerpt(trim(std::string_view(ll.text).substr(from)), 200));
    } else if (name == "pragma") {
        const size_t j = skipSpace(toks, i);
        if (j < toks.size() && toks[j].text == "once") m_onceFiles.insert(normalizePath(f.path));
    } else if (name == "line") {
        doLine(f, ll, toks, i, dirCol);
    } else {
        m_diags.error("P1008", at(nameCol), "unknown preprocessor directive '#" + excerpt(name) + "'");
    }
}

void Preprocessor::extraTokens(const std::vector<Token>& toks, size_t i, std::string_view dir) {
    i = skipSpace(toks, i);
    if (i < toks.size())
        m_diags.warning("P1015", at(toks[i].col),
                        "extra tokens after " + std::string(dir) + " ignored ('" + excerpt(toks[i].text) + "')");
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
        m_diags.warning("P1015", at(nameCol), "extra tokens after #include ignored ('" + excerpt(trim(rest)) + "')");

    const int maxDepth = std::min(m_opts.maxIncludeDepth, kHardIncludeDepth);
    if (depth + 1 > maxDepth) {
        m_diags.error(
            "P1004", at(nameCol),
            "#include nested too deeply (limit " + std::to_string(maxDepth) + ") including '" + excerpt(name) + "'");
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
        for (const std::string& c : candidates) searched += (searched.empty() ? "" : ", ") + excerpt(c);
        m_diags.error("P1003", at(nameCol),
                      "cannot open include file '" + excerpt(name) + "' (tried " + searched + ")");
        return;
    }
    const std::string key = normalizePath(found);
    if (m_onceFiles.count(key)) return;
    if (std::find(m_includeStack.begin(), m_includeStack.end(), key) != m_includeStack.end()) {
        m_diags.error("P1004", at(nameCol), "recursive #include of '" + excerpt(found) + "'");
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

}  // namespace preprocessor_detail

std::vector<PreprocessedLine> preprocess(std::string_view source, const std::string& fileName,
                                         const PreprocessOptions& options, Diagnostics& diags) {
    preprocessor_detail::Preprocessor pp(options, diags);
    return pp.run(source, fileName);
}

}  // namespace ps11
