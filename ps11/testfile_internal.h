// Internals of the .ps11test reader shared by its two files: testfile.cpp (sections, values,
// resources and state) and testfile_commands.cpp (the [test] commands and whole-file checks).
// Not part of the public interface; include ps11/testfile.h instead.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ps11/diagnostics.h"
#include "ps11/suggest.h"
#include "ps11/testfile.h"

namespace ps11::testfile_detail {

using Tokens = std::vector<std::string_view>;

inline char lowerChar(char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; }

inline bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (lowerChar(a[i]) != lowerChar(b[i])) return false;
    return true;
}

inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
inline bool isDigit(char c) { return c >= '0' && c <= '9'; }

inline std::string_view trim(std::string_view s) {
    while (!s.empty() && isSpace(s.front())) s.remove_prefix(1);
    while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
    return s;
}

// Splits a line into tokens at white space; '(' ')' ',' are tokens of their own and '%' starts
// a comment that runs to the end of the line.
inline Tokens tokenize(std::string_view line) {
    Tokens toks;
    size_t i = 0;
    while (i < line.size()) {
        char c = line[i];
        if (c == '%') break;
        if (isSpace(c)) {
            ++i;
        } else if (c == '(' || c == ')' || c == ',') {
            toks.push_back(line.substr(i, 1));
            ++i;
        } else {
            size_t start = i;
            while (i < line.size() && !isSpace(line[i]) && line[i] != '(' && line[i] != ')' && line[i] != ',' &&
                   line[i] != '%')
                ++i;
            toks.push_back(line.substr(start, i - start));
        }
    }
    return toks;
}

inline bool isHexToken(std::string_view s) { return s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X'); }

// True if the token is meant as a number (it may still be a malformed one).
inline bool looksNumeric(std::string_view s) {
    if (s.empty()) return false;
    size_t i = (s[0] == '-' || s[0] == '+') ? 1 : 0;
    if (i < s.size() && s[i] == '.') ++i;
    return i < s.size() && isDigit(s[i]);
}

inline std::optional<uint32_t> parseHex(std::string_view s) {
    if (!isHexToken(s) || s.size() > 10) return std::nullopt;
    uint32_t v = 0;
    for (char c : s.substr(2)) {
        int d;
        if (isDigit(c))
            d = c - '0';
        else if (c >= 'a' && c <= 'f')
            d = c - 'a' + 10;
        else if (c >= 'A' && c <= 'F')
            d = c - 'A' + 10;
        else
            return std::nullopt;
        v = v * 16 + uint32_t(d);
    }
    return v;
}

// A decimal float (`0.5`, `-1`, `1e-3`) or a hex integer (`0xff`); finite values only.
inline std::optional<double> parseNumber(std::string_view s) {
    if (isHexToken(s)) {
        std::optional<uint32_t> h = parseHex(s);
        if (!h) return std::nullopt;
        return double(*h);
    }
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    if (s.empty() || !looksNumeric(s)) return std::nullopt;
    double v = 0;
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
    if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

// A 32-bit word: hex, or a decimal integer.
inline std::optional<uint32_t> parseWord(std::string_view s) {
    if (isHexToken(s)) return parseHex(s);
    std::optional<double> v = parseNumber(s);
    if (!v || *v < 0 || *v > 4294967295.0 || *v != std::floor(*v)) return std::nullopt;
    return uint32_t(*v);
}


template <class E, size_t N>
inline std::optional<E> lookup(const NameEntry<E> (&table)[N], std::string_view name) {
    for (const NameEntry<E>& e : table)
        if (iequals(name, e.name)) return e.value;
    return std::nullopt;
}

// "; did you mean 'linear'?" for a word close to one of the table's names (ps11/suggest.h).
template <class E, size_t N>
inline std::string suggestName(const NameEntry<E> (&table)[N], std::string_view word) {
    std::vector<std::string_view> names;
    for (const NameEntry<E>& e : table) names.push_back(e.name);
    return didYouMean(word, names);
}

template <class E, size_t N>
inline std::string namesOf(const NameEntry<E> (&table)[N]) {
    std::string s;
    for (size_t i = 0; i < N; ++i) s += (i ? (i + 1 == N ? " or " : ", ") : "") + std::string(table[i].name);
    return s;
}

inline const NameEntry<Precision> kPrecisions[] = {
    {"fx8", Precision::Fx8},
    {"fx12", Precision::Fx12},
    {"float", Precision::Float},
    {"ideal", Precision::Ideal},
};
inline const NameEntry<Backend> kBackends[] = {{"emu", Backend::Emu}, {"gl", Backend::Gl}};
// Reads the arguments of one line left to right, reporting what is missing or malformed.
class Args {
public:
    Args(const Tokens& toks, size_t pos, uint32_t line, std::vector<TestFileError>& errors)
        : m_toks(toks), m_pos(pos), m_line(line), m_errors(errors) {}

    bool atEnd() const { return m_pos >= m_toks.size(); }
    std::string_view peek() const { return atEnd() ? std::string_view() : m_toks[m_pos]; }
    std::string_view next() { return atEnd() ? std::string_view() : m_toks[m_pos++]; }
    bool peekIs(std::string_view word) const { return !atEnd() && iequals(m_toks[m_pos], word); }
    bool peekNumeric() const { return !atEnd() && looksNumeric(m_toks[m_pos]); }
    size_t pos() const { return m_pos; }
    uint32_t line() const { return m_line; }

    void error(std::string message) { m_errors.push_back({m_line, std::move(message)}); }

    // Reports "missing WHAT" at the end of the line.
    bool need(const std::string& what) {
        if (!atEnd()) return true;
        error("missing " + what);
        return false;
    }

    std::optional<double> number(const std::string& what) {
        if (!need(what)) return std::nullopt;
        std::string_view t = next();
        std::optional<double> v = parseNumber(t);
        if (!v) error("bad number " + quote(t) + " for " + what);
        return v;
    }

    std::optional<float> floatValue(const std::string& what) {
        std::optional<double> v = number(what);
        if (!v) return std::nullopt;
        if (std::fabs(*v) > double(std::numeric_limits<float>::max())) {
            error(what + " is out of range");
            return std::nullopt;
        }
        return float(*v);
    }

    std::optional<int64_t> integer(const std::string& what, int64_t lo, int64_t hi) {
        std::optional<double> v = number(what);
        if (!v) return std::nullopt;
        if (*v != std::floor(*v)) {
            error(what + " must be an integer, not " + quote(m_toks[m_pos - 1]));
            return std::nullopt;
        }
        if (*v < double(lo) || *v > double(hi)) {
            error(what + " " + quote(m_toks[m_pos - 1]) + " is out of range (" + std::to_string(lo) + " to " +
                  std::to_string(hi) + ")");
            return std::nullopt;
        }
        return int64_t(*v);
    }

    std::optional<uint32_t> word(const std::string& what) {
        if (!need(what)) return std::nullopt;
        std::string_view t = next();
        std::optional<uint32_t> v = parseWord(t);
        if (!v) error("bad " + what + " " + quote(t) + " (expected a 32-bit word, e.g. 0xff808080)");
        return v;
    }

    // n floats into out[0..n).
    bool floats(float* out, int n, const std::string& what) {
        bool ok = true;
        for (int i = 0; i < n; ++i) {
            std::optional<float> v = floatValue(what);
            if (!v) {
                ok = false;
                if (atEnd()) break;
            } else {
                out[i] = *v;
            }
        }
        return ok;
    }

    // A colour: one word 0xAARRGGBB (hex, or a lone decimal integer), or `channels` floats.
    std::optional<Color> color(const std::string& what, int channels = 4) {
        if (!need(what)) return std::nullopt;
        size_t count = 0;
        while (m_pos + count < m_toks.size() && looksNumeric(m_toks[m_pos + count])) ++count;
        if (isHexToken(peek()) || count == 1) {
            std::optional<uint32_t> w = word(what);
            if (!w) return std::nullopt;
            return Color::fromArgb(*w);
        }
        if (count < size_t(channels)) {
            if (count == 0)
                error("bad " + what + " " + quote(next()));
            else
                error(what + " needs one 0xAARRGGBB word or " + std::to_string(channels) + " floats");
            m_pos += count;
            return std::nullopt;
        }
        Vec4 v{0, 0, 0, 1};
        if (!floats(v.data(), channels, what)) return std::nullopt;
        return Color::fromFloats(v);
    }

    template <class E, size_t N>
    std::optional<E> name(const NameEntry<E> (&table)[N], const std::string& what) {
        if (!need(what + " (" + namesOf(table) + ")")) return std::nullopt;
        std::string_view t = next();
        std::optional<E> v = lookup(table, t);
        if (!v)
            error("unknown " + what + " " + quote(t) + " (expected " + namesOf(table) + ")" + suggestName(table, t));
        return v;
    }

    // Reports anything left on the line.
    void end() {
        if (!atEnd()) error("unexpected " + quote(peek()) + " at the end of the line");
    }

private:
    const Tokens& m_toks;
    size_t m_pos;
    uint32_t m_line;
    std::vector<TestFileError>& m_errors;
};

// "unknown keyword 'sise' in [render target] (expected size, format, clear or depth); did you
// mean 'size'?". `expected` replaces the listed names in the message where a short form reads
// better (colorarg0-2); the suggestion always looks at every name.
inline void unknownKeyword(Args& a, std::string_view kw, std::string_view section,
                           std::initializer_list<std::string_view> names, std::string_view expected = {}) {
    std::string list(expected);
    if (list.empty()) {
        size_t i = 0;
        for (std::string_view n : names) list += (i++ ? (i == names.size() ? " or " : ", ") : "") + std::string(n);
    }
    a.error("unknown keyword " + quote(kw) + " in [" + std::string(section) + "] (expected " + list + ")" +
            didYouMean(kw, names));
}

template <class T>
void assign(Setting<T>& s, const std::optional<T>& v, uint32_t line) {
    if (v) {
        s.value = *v;
        s.line = line;
    }
}

// "t3" → 3 (prefix letter checked case-insensitively); nullopt when it is not that shape.
inline std::optional<int> registerIndex(std::string_view t, char prefix) {
    if (t.size() < 2 || t.size() > 3 || lowerChar(t[0]) != prefix) return std::nullopt;
    int v = 0;
    for (char c : t.substr(1)) {
        if (!isDigit(c)) return std::nullopt;
        v = v * 10 + (c - '0');
    }
    return v;
}

enum class Section {
    None,
    Require,
    RenderTarget,
    Texture,
    Sampler,
    Stage,
    RenderState,
    Transform,
    Constants,
    PixelShader,
    Test
};

class Parser {
public:
    Parser(TestFile& out, std::vector<TestFileError>& errors) : m_file(out), m_errors(errors) {}

    void run(std::string_view text);

private:
    void error(uint32_t line, std::string message) { m_errors.push_back({line, std::move(message)}); }

    void sectionLine(uint32_t line, std::string_view trimmed);
    void openSection(uint32_t line, const Tokens& toks);
    void closeSection();
    void contentLine(uint32_t line, const Tokens& toks);
    bool once(Section s, uint32_t line, const char* name);

    void requireLine(Args& a, std::string_view kw);
    void renderTargetLine(Args& a, std::string_view kw);
    void textureLine(Args& a, std::string_view kw);
    void texelRow(Args& a);
    void startLevel(uint32_t level, uint32_t line);
    bool checkTexel(Args& a, const Texel& v);
    void closeLevel();
    void closeTexture();
    void samplerLine(Args& a, std::string_view kw);
    void stageLine(Args& a, std::string_view kw);
    void renderStateLine(Args& a, std::string_view kw);
    void transformLine(Args& a, std::string_view kw);
    void constantsLine(Args& a, std::string_view kw);
    void testLine(uint32_t line, const Tokens& toks);
    bool conditionPrefix(Args& a, Condition& cond);
    bool drawCommand(Args& a, TestCommand& cmd);
    void vertexLine(Args& a, DrawPrimitives& draw);
    void evalLine(Args& a, Eval& eval);
    bool probeCommand(Args& a, TestCommand& cmd);
    bool probeTolerance(Args& a, Probe& p);
    void closePending();
    void finish();

    std::optional<Texel> texel(Args& a);
    std::optional<TextureArg> textureArg(Args& a, bool resultArg);

    TestFile& m_file;
    std::vector<TestFileError>& m_errors;
    Section m_section = Section::None;
    size_t m_index = 0;  // current texture/sampler/stage in its vector
    std::vector<Section> m_seen;
    // Texture data being read.
    bool m_inLevel = false;
    size_t m_levelRows = 0;
    // [test]: the draw or eval whose following lines are being read.
    // Skip swallows the lines following a command line that was in error.
    enum class Pending { None, Draw, Eval, Skip } m_pending = Pending::None;
    bool m_sawSectionLine = false;
};

}  // namespace ps11::testfile_detail
