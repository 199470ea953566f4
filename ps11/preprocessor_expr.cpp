// Preprocessor stage, #if part: expands a #if/#elif line, then evaluates it as a C integer
// expression (recursive descent with C precedence, defined(), short-circuit operands where
// division by zero is no error). Lines, directives and macros are in preprocessor.cpp and
// preprocessor_macros.cpp.
#include "ps11/preprocessor_internal.h"

namespace ps11::preprocessor_detail {

// Recursive-descent evaluator with C precedence; `eval` false marks operands that short-circuit
// away, where division by zero is not an error (as in C).
class Preprocessor::Expr {
public:
    Expr(Preprocessor& pp, const std::vector<Token>& toks, uint32_t endCol) : m_pp(pp), m_t(toks), m_endCol(endCol) {}

    std::optional<int64_t> run() {
        const int64_t v = ternary(true);
        if (!m_failed && m_i < m_t.size()) fail(m_t[m_i].col, "unexpected '" + excerpt(m_t[m_i].text) + "' in #if");
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
        fail(t.col, "unexpected '" + excerpt(t.text) + "' in #if expression");
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
            fail(t.col, "invalid integer constant '" + excerpt(t.text) + "' in #if (only integers are allowed)");
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

}  // namespace ps11::preprocessor_detail
