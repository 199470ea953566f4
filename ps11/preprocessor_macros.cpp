// Preprocessor stage, macro part: #define and #undef, and expansion of object- and
// function-like macros (Prosser's hide-set algorithm, with # and ##) under a work budget.
// Lines, directives and #include are in preprocessor.cpp; #if expressions in
// preprocessor_expr.cpp.
#include <memory>
#include <string>
#include <vector>

#include "ps11/preprocessor_internal.h"

namespace ps11::preprocessor_detail {

void Preprocessor::doDefine(const std::vector<Token>& toks, size_t i, uint32_t endCol) {
    i = skipSpace(toks, i);
    if (i >= toks.size() || toks[i].kind != TokKind::Ident) {
        if (i >= toks.size())
            m_diags.error("P1005", at(endCol), "#define needs a macro name");
        else
            m_diags.error("P1005", at(toks[i].col),
                          "macro name must be an identifier, not '" + excerpt(toks[i].text) + "'");
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
                m_diags.error("P1005", at(endCol),
                              "missing ')' in the parameter list of macro '" + excerpt(nameTok.text) + "'");
                return;
            }
            const Token& t = toks[i];
            if (first && isPunct(t, ")")) {
                ++i;
                break;
            }
            if (t.kind == TokKind::Ident) {
                if (t.text == "__VA_ARGS__" || std::find(m.params.begin(), m.params.end(), t.text) != m.params.end()) {
                    m_diags.error("P1005", at(t.col),
                                  "duplicate or reserved macro parameter '" + excerpt(t.text) + "'");
                    return;
                }
                m.params.push_back(t.text);
            } else if (isPunct(t, "...")) {
                m.variadic = true;
                m.params.push_back("__VA_ARGS__");
            } else {
                m_diags.error("P1005", at(t.col),
                              "expected a parameter name in macro '" + excerpt(nameTok.text) + "', found '" +
                                  excerpt(t.text) + "'");
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
                          m.variadic
                              ? "'...' must be the last parameter of macro '" + excerpt(nameTok.text) + "'"
                              : "expected ',' or ')' in the parameter list of macro '" + excerpt(nameTok.text) + "'");
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
                      "'##' cannot appear at either end of the body of macro '" + excerpt(nameTok.text) + "'");
        return;
    }
    if (m.functionLike) {
        for (size_t k = 0; k < m.body.size(); ++k) {
            if (!isPunct(m.body[k], "#")) continue;
            size_t n = k + 1;
            if (n < m.body.size() && m.body[n].kind == TokKind::Space) ++n;
            if (n >= m.body.size() || m.paramIndex(m.body[n]) < 0) {
                m_diags.error(
                    "P1005", at(m.body[k].col),
                    "'#' is not followed by a parameter in the body of macro '" + excerpt(nameTok.text) + "'");
                return;
            }
        }
    }
    m.nameId = nameId(nameTok.text);
    auto it = m_macros.find(nameTok.text);
    if (it != m_macros.end()) {
        if (!it->second.sameAs(m)) {
            m_diags.warning("P1013", m.loc, "macro '" + excerpt(nameTok.text) + "' redefined with a different body");
            m_diags.note(it->second.loc, "previous definition of '" + excerpt(nameTok.text) + "' is here");
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
                m_diags.error("P1011", at(t.col),
                              "unterminated argument list invoking macro '" + excerpt(t.text) + "'");
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
                              "macro '" + excerpt(t.text) + "' expects " + std::to_string(np) +
                                  (m.variadic ? " or more" : "") + " argument" + (np == 1 ? "" : "s") + ", got " +
                                  std::to_string(args.size()));
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

}  // namespace ps11::preprocessor_detail
