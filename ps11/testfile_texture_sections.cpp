// The .ps11test reader, its [texture N] and [sampler N] sections (ps11/testfile.cpp reads the
// file line by line and the other sections; docs/test-format.md): a texture's size, format,
// levels and texel rows or fills, each level checked as it closes, and a sampler's filters and
// address modes. Every problem is an error with its file line, and parsing goes on.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "ps11/testfile.h"
#include "ps11/testfile_internal.h"

namespace ps11 {
namespace testfile_detail {
namespace {

const NameEntry<Filter> kFilters[] = {{"point", Filter::Point}, {"linear", Filter::Linear}};
const NameEntry<Filter> kMipFilters[] = {{"none", Filter::None}, {"point", Filter::Point}, {"linear", Filter::Linear}};
const NameEntry<TextureAddress> kAddressModes[] = {
    {"wrap", TextureAddress::Wrap},     {"clamp", TextureAddress::Clamp},           {"mirror", TextureAddress::Mirror},
    {"border", TextureAddress::Border}, {"mirroronce", TextureAddress::MirrorOnce},
};

uint32_t levelExtent(uint32_t size, uint32_t level) { return level >= 32 ? 1 : std::max<uint32_t>(1, size >> level); }

uint32_t maxLevels(uint32_t w, uint32_t h, uint32_t d) {
    uint32_t m = std::max({w, h, d, 1u}), n = 1;
    while (m > 1) {
        m >>= 1;
        ++n;
    }
    return n;
}

}  // namespace

std::optional<Texel> Parser::texel(Args& a) {
    Texel t;
    if (a.peek() != "(") {
        std::optional<uint32_t> w = a.word("texel");
        if (!w) return std::nullopt;
        t.bits = *w;
        return t;
    }
    a.next();
    while (!a.atEnd() && a.peek() != ")") {
        if (t.count == 4) {
            a.error("a texel has at most 4 floats");
            while (!a.atEnd() && a.peek() != ")") a.next();
            break;
        }
        std::optional<float> v = a.floatValue("texel component");
        if (!v) return std::nullopt;
        t.value[t.count++] = *v;
    }
    if (a.atEnd()) {
        a.error("missing ')' after the texel's floats");
        return std::nullopt;
    }
    a.next();
    if (t.count == 0) {
        a.error("empty texel '()'");
        return std::nullopt;
    }
    return t;
}

void Parser::textureLine(Args& a, std::string_view kw) {
    TextureDesc& t = m_file.textures[m_index];
    uint32_t line = a.line();
    bool hasData = !t.data.empty();
    auto beforeData = [&](const char* what) {
        if (hasData) a.error(std::string("'") + what + "' must come before the texel data");
        return !hasData;
    };
    if (iequals(kw, "size")) {
        if (!beforeData("size")) return;
        std::optional<int64_t> w = a.integer("texture width", 1, kMaxTextureSide);
        std::optional<int64_t> h = a.integer("texture height", 1, kMaxTextureSide);
        std::optional<int64_t> d = std::optional<int64_t>(0);
        if (!a.atEnd()) d = a.integer("volume texture depth", 1, kMaxVolumeSide);
        if (w && h && d) {
            uint64_t texels = uint64_t(*w) * uint64_t(*h) * uint64_t(std::max<int64_t>(*d, 1));
            if (texels > kMaxTexels) {
                a.error("texture is too large (" + std::to_string(texels) + " texels, at most " +
                        std::to_string(kMaxTexels) + ")");
            } else {
                t.width = uint32_t(*w);
                t.height = uint32_t(*h);
                t.depth = uint32_t(*d);
                t.sizeLine = line;
            }
        }
    } else if (iequals(kw, "format")) {
        if (!beforeData("format")) return;
        assign(t.format, a.name(kTexFormatNames, "texture format"), line);
    } else if (iequals(kw, "levels")) {
        if (!beforeData("levels")) return;
        std::optional<int64_t> n = a.integer("levels", 0, 15);
        if (n) t.levels = {uint32_t(*n), line};
    } else if (iequals(kw, "level")) {
        if (t.sizeLine == 0) {
            a.error("'level' needs the texture's 'size' first");
            return;
        }
        uint32_t count = t.levels.value ? t.levels.value : 1;
        std::optional<int64_t> n = a.integer("level", 0, 15);
        if (!n) return;
        if (*n >= int64_t(count)) {
            a.error("level " + std::to_string(*n) + " is beyond the texture's " + std::to_string(count) +
                    (t.levels.value ? " levels" : " level (levels 0 builds the chain from level 0)"));
            return;
        }
        closeLevel();
        for (const TextureLevel& l : t.data)
            if (l.level == uint32_t(*n)) {
                a.error("level " + std::to_string(*n) + " given twice (first at line " + std::to_string(l.line) + ")");
                return;
            }
        startLevel(uint32_t(*n), line);
    } else if (iequals(kw, "fill")) {
        if (t.sizeLine == 0) {
            a.error("'fill' needs the texture's 'size' first");
            return;
        }
        if (!m_inLevel && !t.data.empty()) {
            a.error("'fill' outside a level (write 'level N' before it)");
            return;
        }
        if (m_inLevel && (m_levelRows > 0 || t.data.back().hasFill)) {
            a.error("'fill' after texel rows or another 'fill' of the same level");
            return;
        }
        if (!m_inLevel) startLevel(0, line);  // a lone `fill` is level 0
        if (!a.need("fill texel")) return;
        std::optional<Texel> v = texel(a);
        if (!v || !checkTexel(a, *v)) return;
        t.data.back().hasFill = true;
        t.data.back().fill = *v;
    } else {
        unknownKeyword(a, kw, "texture", {"size", "format", "levels", "level", "fill"});
        return;
    }
    a.end();
}

void Parser::startLevel(uint32_t level, uint32_t line) {
    TextureDesc& t = m_file.textures[m_index];
    TextureLevel l;
    l.line = line;
    l.level = level;
    l.width = levelExtent(t.width, level);
    l.height = levelExtent(t.height, level);
    l.depth = t.isVolume() ? levelExtent(t.depth, level) : 1;
    t.data.push_back(std::move(l));
    m_inLevel = true;
    m_levelRows = 0;
}

bool Parser::checkTexel(Args& a, const Texel& v) {
    TexFormat f = m_file.textures[m_index].format.value;
    int bits = formatBits(f);
    if (isFloatFormat(f) && v.count == 0) {
        a.error(std::string("format ") + texFormatName(f) + " takes float texels in parentheses, e.g. (0.5 0.25 0 1)");
    } else if (!isFloatFormat(f) && v.count > 0) {
        a.error(std::string("format ") + texFormatName(f) + " takes one hex word per texel, not floats in parentheses");
    } else if (f == TexFormat::R32F && v.count > 1) {
        a.error("format R32F takes one float per texel");
    } else if (v.count == 0 && bits < 32 && (v.bits >> bits) != 0) {
        char buf[16];
        std::snprintf(buf, sizeof buf, "0x%x", v.bits);
        a.error(std::string("texel ") + buf + " does not fit format " + texFormatName(f) + " (" + std::to_string(bits) +
                " bits)");
    } else {
        return true;
    }
    return false;
}

void Parser::texelRow(Args& a) {
    TextureDesc& t = m_file.textures[m_index];
    if (!m_inLevel) {
        a.error("texel row outside a level (write 'level 0' before the rows)");
        return;
    }
    TextureLevel& l = t.data.back();
    if (l.hasFill) {
        a.error("texel row after 'fill' (a level is either filled or given row by row)");
        return;
    }
    ++m_levelRows;
    size_t count = 0;
    while (!a.atEnd()) {
        std::optional<Texel> v = texel(a);
        ++count;
        if (v && checkTexel(a, *v)) l.texels.push_back(*v);
    }
    if (count != l.width) {
        a.error("texel row has " + std::to_string(count) + " texels, level " + std::to_string(l.level) + " is " +
                std::to_string(l.width) + " wide");
    }
}

void Parser::closeLevel() {
    if (!m_inLevel) return;
    m_inLevel = false;
    TextureDesc& t = m_file.textures[m_index];
    TextureLevel& l = t.data.back();
    if (l.hasFill) return;
    uint64_t rows = uint64_t(l.height) * l.depth;
    if (m_levelRows != rows) {
        error(l.line, "level " + std::to_string(l.level) + " has " + std::to_string(m_levelRows) +
                          " texel rows, expected " + std::to_string(rows) +
                          (t.isVolume() ? " (height x depth, slice after slice)" : " (its height)") +
                          (m_levelRows == 0 ? "; or use 'fill'" : ""));
    }
    if (l.texels.size() != uint64_t(l.width) * rows) l.texels.clear();  // incomplete: reported above
}

void Parser::closeTexture() {
    closeLevel();
    TextureDesc& t = m_file.textures[m_index];
    if (t.sizeLine == 0) {
        error(t.line, "[texture " + std::to_string(t.stage) + "] needs a 'size'");
        return;
    }
    uint32_t possible = maxLevels(t.width, t.height, t.depth);
    if (t.levels.value > possible) {
        error(t.levels.line, "levels " + std::to_string(t.levels.value) + " is more than a " + std::to_string(t.width) +
                                 "x" + std::to_string(t.height) + " texture has (" + std::to_string(possible) + ")");
    }
    std::sort(t.data.begin(), t.data.end(),
              [](const TextureLevel& x, const TextureLevel& y) { return x.level < y.level; });
    uint32_t needed = std::max<uint32_t>(1, t.levels.value);
    for (uint32_t k = 0; k < needed && k < possible; ++k) {
        bool found = std::any_of(t.data.begin(), t.data.end(), [k](const TextureLevel& l) { return l.level == k; });
        if (!found)
            error(t.line, "[texture " + std::to_string(t.stage) + "] has no data for level " + std::to_string(k) +
                              " (write 'level " + std::to_string(k) + "' and its rows, or 'fill')");
    }
}

void Parser::samplerLine(Args& a, std::string_view kw) {
    SamplerDesc& s = m_file.samplers[m_index];
    uint32_t line = a.line();
    if (iequals(kw, "filter")) {
        std::optional<Filter> minF = a.name(kFilters, "filter");
        std::optional<Filter> magF = minF;
        if (!a.atEnd() && !a.peekIs("mip")) magF = a.name(kFilters, "mag filter");
        assign(s.minFilter, minF, line);
        assign(s.magFilter, magF, line);
        if (a.peekIs("mip")) {
            a.next();
            assign(s.mipFilter, a.name(kMipFilters, "mip filter"), line);
        }
    } else if (iequals(kw, "address")) {
        std::optional<TextureAddress> u = a.name(kAddressModes, "address mode");
        std::optional<TextureAddress> v = u, w = u;
        if (!a.atEnd()) v = w = a.name(kAddressModes, "v address mode");
        if (!a.atEnd()) w = a.name(kAddressModes, "w address mode");
        assign(s.addressU, u, line);
        assign(s.addressV, v, line);
        assign(s.addressW, w, line);
    } else if (iequals(kw, "border")) {
        assign(s.border, a.color("border colour"), line);
    } else {
        unknownKeyword(a, kw, "sampler", {"filter", "address", "border"});
        return;
    }
    a.end();
}

}  // namespace testfile_detail
}  // namespace ps11
