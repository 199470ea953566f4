// The .ps11test reader (stage: test input, before the device and the executor), sections part:
// line by line, '%' comment and blank lines are skipped outside [pixel shader], a `[...]` line
// opens a section, every other line is a keyword line of that section or a texel row. Every
// problem is collected as an error with its file line and parsing goes on. The [texture N] and
// [sampler N] sections are read in testfile_texture_sections.cpp; the [test] commands and the
// whole-file checks in testfile_commands.cpp.
#include "ps11/testfile.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "ps11/testfile_internal.h"

namespace ps11 {
namespace testfile_detail {
namespace {

const NameEntry<TextureOp> kTextureOps[] = {
    {"disable", TextureOp::Disable},
    {"selectarg1", TextureOp::SelectArg1},
    {"selectarg2", TextureOp::SelectArg2},
    {"modulate", TextureOp::Modulate},
    {"modulate2x", TextureOp::Modulate2x},
    {"modulate4x", TextureOp::Modulate4x},
    {"add", TextureOp::Add},
    {"addsigned", TextureOp::AddSigned},
    {"addsigned2x", TextureOp::AddSigned2x},
    {"subtract", TextureOp::Subtract},
    {"addsmooth", TextureOp::AddSmooth},
    {"blenddiffusealpha", TextureOp::BlendDiffuseAlpha},
    {"blendtexturealpha", TextureOp::BlendTextureAlpha},
    {"blendfactoralpha", TextureOp::BlendFactorAlpha},
    {"blendtexturealphapm", TextureOp::BlendTextureAlphaPm},
    {"blendcurrentalpha", TextureOp::BlendCurrentAlpha},
    {"premodulate", TextureOp::PreModulate},
    {"modulatealpha_addcolor", TextureOp::ModulateAlphaAddColor},
    {"modulatecolor_addalpha", TextureOp::ModulateColorAddAlpha},
    {"modulateinvalpha_addcolor", TextureOp::ModulateInvAlphaAddColor},
    {"modulateinvcolor_addalpha", TextureOp::ModulateInvColorAddAlpha},
    {"bumpenvmap", TextureOp::BumpEnvMap},
    {"bumpenvmapluminance", TextureOp::BumpEnvMapLuminance},
    {"dotproduct3", TextureOp::DotProduct3},
    {"multiplyadd", TextureOp::MultiplyAdd},
    {"lerp", TextureOp::Lerp},
};
const NameEntry<ArgSource> kArgSources[] = {
    {"diffuse", ArgSource::Diffuse}, {"current", ArgSource::Current},   {"texture", ArgSource::Texture},
    {"tfactor", ArgSource::TFactor}, {"specular", ArgSource::Specular}, {"temp", ArgSource::Temp},
};
const NameEntry<Blend> kBlends[] = {
    {"zero", Blend::Zero},
    {"one", Blend::One},
    {"srccolor", Blend::SrcColor},
    {"invsrccolor", Blend::InvSrcColor},
    {"srcalpha", Blend::SrcAlpha},
    {"invsrcalpha", Blend::InvSrcAlpha},
    {"destalpha", Blend::DestAlpha},
    {"invdestalpha", Blend::InvDestAlpha},
    {"destcolor", Blend::DestColor},
    {"invdestcolor", Blend::InvDestColor},
    {"srcalphasat", Blend::SrcAlphaSat},
    {"bothsrcalpha", Blend::BothSrcAlpha},
    {"bothinvsrcalpha", Blend::BothInvSrcAlpha},
    {"blendfactor", Blend::BlendFactor},
    {"invblendfactor", Blend::InvBlendFactor},
};
const NameEntry<BlendOp> kBlendOps[] = {
    {"add", BlendOp::Add}, {"subtract", BlendOp::Subtract}, {"revsubtract", BlendOp::RevSubtract},
    {"min", BlendOp::Min}, {"max", BlendOp::Max},
};
const NameEntry<CompareFunc> kCompareFuncs[] = {
    {"never", CompareFunc::Never},
    {"less", CompareFunc::Less},
    {"equal", CompareFunc::Equal},
    {"lessequal", CompareFunc::LessEqual},
    {"greater", CompareFunc::Greater},
    {"notequal", CompareFunc::NotEqual},
    {"greaterequal", CompareFunc::GreaterEqual},
    {"always", CompareFunc::Always},
};
const NameEntry<CullMode> kCullModes[] = {{"none", CullMode::None}, {"cw", CullMode::Cw}, {"ccw", CullMode::Ccw}};
const NameEntry<bool> kOnOff[] = {{"on", true}, {"off", false}};

}  // namespace

void Parser::run(std::string_view text) {
    uint32_t line = 0;
    size_t pos = 0;
    while (pos <= text.size()) {
        size_t nl = text.find('\n', pos);
        if (nl == std::string_view::npos) nl = text.size();
        std::string_view raw = text.substr(pos, nl - pos);
        bool lastLine = nl == text.size();
        pos = nl + 1;
        if (lastLine && raw.empty() && line > 0) break;  // the file ends with a newline
        ++line;
        if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
        std::string_view trimmed = trim(raw);
        if (m_section == Section::PixelShader && (trimmed.empty() || trimmed[0] != '[')) {
            PixelShaderBlock& ps = m_file.pixelShader;
            if (line > ps.firstLine) ps.text += '\n';
            if (trimmed.empty() || trimmed[0] != '%') ps.text += raw;
            continue;
        }
        if (trimmed.empty() || trimmed[0] == '%') continue;
        if (trimmed[0] == '[') {
            sectionLine(line, trimmed);
            continue;
        }
        contentLine(line, tokenize(trimmed));
    }
    closeSection();
    finish();
}

void Parser::sectionLine(uint32_t line, std::string_view trimmed) {
    closeSection();
    m_sawSectionLine = true;
    size_t close = trimmed.find(']');
    if (close == std::string_view::npos) {
        error(line, "section line " + quote(trimmed) + " has no closing ']'");
        return;
    }
    Tokens rest = tokenize(trimmed.substr(close + 1));
    if (!rest.empty()) error(line, "unexpected " + quote(rest[0]) + " after the section name");
    Tokens toks = tokenize(trimmed.substr(1, close - 1));
    if (toks.empty()) {
        error(line, "empty section name");
        return;
    }
    openSection(line, toks);
}

bool Parser::once(Section s, uint32_t line, const char* name) {
    if (std::find(m_seen.begin(), m_seen.end(), s) != m_seen.end()) {
        error(line, std::string("duplicate section [") + name + "]");
        return false;
    }
    m_seen.push_back(s);
    return true;
}

void Parser::openSection(uint32_t line, const Tokens& toks) {
    auto is = [&](size_t i, std::string_view w) { return i < toks.size() && iequals(toks[i], w); };
    Args a(toks, 1, line, m_errors);
    if (is(0, "require") && toks.size() == 1) {
        if (once(Section::Require, line, "require")) m_section = Section::Require;
        m_file.require.line = line;
    } else if (is(0, "render") && is(1, "target") && toks.size() == 2) {
        if (once(Section::RenderTarget, line, "render target")) m_section = Section::RenderTarget;
        m_file.renderTarget.line = line;
    } else if (is(0, "render") && is(1, "state") && toks.size() == 2) {
        if (once(Section::RenderState, line, "render state")) m_section = Section::RenderState;
        m_file.renderState.line = line;
    } else if (is(0, "transform") && toks.size() == 1) {
        if (once(Section::Transform, line, "transform")) m_section = Section::Transform;
        m_file.transform.line = line;
    } else if (is(0, "constants") && toks.size() == 1) {
        if (once(Section::Constants, line, "constants")) m_section = Section::Constants;
    } else if (is(0, "test") && toks.size() == 1) {
        if (once(Section::Test, line, "test")) m_section = Section::Test;
        m_file.testLine = line;
    } else if (is(0, "texture") || is(0, "sampler") || is(0, "stage")) {
        std::string what = std::string(toks[0]) + " stage";
        std::optional<int64_t> n = a.integer("[" + std::string(toks[0]) + " N] " + what, 0, 7);
        a.end();
        if (!n) return;
        int stage = int(*n);
        auto duplicate = [&](const auto& vec) {
            for (const auto& d : vec)
                if (d.stage == stage) {
                    error(line, "duplicate section [" + std::string(toks[0]) + " " + std::to_string(stage) +
                                    "] (first at line " + std::to_string(d.line) + ")");
                    return true;
                }
            return false;
        };
        if (is(0, "texture")) {
            if (duplicate(m_file.textures)) return;
            TextureDesc t;
            t.line = line;
            t.stage = stage;
            m_file.textures.push_back(std::move(t));
            m_index = m_file.textures.size() - 1;
            m_section = Section::Texture;
            m_inLevel = false;
        } else if (is(0, "sampler")) {
            if (duplicate(m_file.samplers)) return;
            SamplerDesc s;
            s.line = line;
            s.stage = stage;
            m_file.samplers.push_back(s);
            m_index = m_file.samplers.size() - 1;
            m_section = Section::Sampler;
        } else {
            if (duplicate(m_file.stages)) return;
            StageDesc s = defaultStage(stage);
            s.line = line;
            m_file.stages.push_back(s);
            m_index = m_file.stages.size() - 1;
            m_section = Section::Stage;
        }
    } else if (is(0, "pixel") && is(1, "shader")) {
        if (m_file.pixelShader.present()) {
            error(line,
                  "duplicate [pixel shader] section (first at line " + std::to_string(m_file.pixelShader.line) + ")");
            m_section = Section::None;
            return;
        }
        PixelShaderBlock& ps = m_file.pixelShader;
        ps.line = line;
        ps.firstLine = line + 1;
        m_section = Section::PixelShader;
        Args h(toks, 2, line, m_errors);
        if (h.atEnd()) return;
        if (!h.peekIs("fail")) {
            h.error("unexpected " + quote(h.peek()) + " in [pixel shader] (expected 'fail CODE [at LINE:COL]')");
            return;
        }
        h.next();
        ps.expectFail = true;
        if (!h.need("diagnostic code after 'fail' (e.g. P2003)")) return;
        std::string_view code = h.next();
        bool ok = code.size() == 5 && std::isalpha(static_cast<unsigned char>(code[0]));
        for (size_t i = 1; ok && i < 5; ++i) ok = isDigit(code[i]);
        if (!ok) {
            h.error("bad diagnostic code " + quote(code) + " (expected a letter and four digits, e.g. P2003)");
        } else {
            ps.failCode = std::string(code);
            ps.failCode[0] = char(std::toupper(static_cast<unsigned char>(ps.failCode[0])));
        }
        if (h.atEnd()) return;
        if (!h.peekIs("at")) {
            h.error("unexpected " + quote(h.peek()) + " after the code (expected 'at LINE:COL')");
            return;
        }
        h.next();
        if (!h.need("LINE:COL after 'at'")) return;
        std::string_view place = h.next();
        size_t colon = place.find(':');
        std::optional<uint32_t> l = parseWord(place.substr(0, colon));
        std::optional<uint32_t> c =
            colon == std::string_view::npos ? std::optional<uint32_t>(0) : parseWord(place.substr(colon + 1));
        if (isHexToken(place) || !l || !c || *l == 0 || (colon != std::string_view::npos && *c == 0)) {
            h.error("bad place " + quote(place) + " after 'at' (expected LINE:COL, e.g. 3:5)");
        } else {
            ps.failLine = *l;
            ps.failCol = *c;
        }
        h.end();
    } else {
        std::string name;
        for (size_t i = 0; i < toks.size(); ++i) name += (i ? " " : "") + std::string(toks[i]);
        // Suggest from the two-word names first ("render targt"), then the first word ("texure 0").
        std::string hint = didYouMean(name, {"render target", "render state", "pixel shader"});
        if (hint.empty())
            hint = didYouMean(toks[0], {"require", "transform", "constants", "test", "texture", "sampler", "stage"});
        error(line, "unknown section [" + excerpt(name) + "]" + hint);
    }
}

void Parser::closeSection() {
    if (m_section == Section::Texture) closeTexture();
    if (m_section == Section::Test) closePending();
    m_section = Section::None;
}

void Parser::contentLine(uint32_t line, const Tokens& toks) {
    if (toks.empty()) return;
    if (m_section == Section::Test) {
        testLine(line, toks);
        return;
    }
    if (m_section == Section::Texture && (looksNumeric(toks[0]) || toks[0] == "(")) {
        Args a(toks, 0, line, m_errors);
        texelRow(a);
        return;
    }
    std::string_view kw = toks[0];
    Args a(toks, 1, line, m_errors);
    switch (m_section) {
        case Section::None:
            if (!m_sawSectionLine)
                error(line, quote(kw) + " before any section (a section starts with a line like [test])");
            // Otherwise the section line itself was bad and already reported.
            return;
        case Section::Require:
            requireLine(a, kw);
            return;
        case Section::RenderTarget:
            renderTargetLine(a, kw);
            return;
        case Section::Texture:
            textureLine(a, kw);
            return;
        case Section::Sampler:
            samplerLine(a, kw);
            return;
        case Section::Stage:
            stageLine(a, kw);
            return;
        case Section::RenderState:
            renderStateLine(a, kw);
            return;
        case Section::Transform:
            transformLine(a, kw);
            return;
        case Section::Constants:
            constantsLine(a, kw);
            return;
        case Section::PixelShader:
        case Section::Test:
            return;
    }
}

void Parser::requireLine(Args& a, std::string_view kw) {
    RequireDesc& r = m_file.require;
    uint32_t line = a.line();
    if (iequals(kw, "version")) {
        if (!a.need("shader version (ps_1_1 ... ps_1_4)")) return;
        std::string_view v = a.next();
        if (v.size() == 6 && iequals(v.substr(0, 5), "ps_1_") && v[5] >= '1' && v[5] <= '4') {
            r.versionMinor = {v[5] - '0', line};
        } else {
            a.error("unknown shader version " + quote(v) + " (expected ps_1_1, ps_1_2, ps_1_3 or ps_1_4)");
        }
    } else if (iequals(kw, "precision")) {
        assign(r.precision, a.name(kPrecisions, "precision"), line);
    } else if (iequals(kw, "backend")) {
        uint8_t mask = 0;
        a.need("backend (" + namesOf(kBackends) + ")");
        while (!a.atEnd()) {
            if (a.peek() == ",") {
                a.next();
                continue;
            }
            std::optional<Backend> b = a.name(kBackends, "backend");
            if (b) mask |= uint8_t(1u << unsigned(*b));
        }
        if (mask) r.backends = {mask, line};
        return;
    } else if (iequals(kw, "max_value")) {
        std::optional<float> v = a.floatValue("max_value");
        if (v && *v <= 0)
            a.error("max_value must be > 0");
        else
            assign(r.maxValue, v, line);
    } else if (iequals(kw, "hardware")) {
        if (!a.need("hardware class (" + hardwareNames() + ")")) return;
        std::string_view n = a.next();
        const HardwareClass* h = findHardware(n);
        if (!h) {
            a.error(unknownHardwareMessage(n));
            return;
        }
        if (r.hardware.isSet()) a.error("hardware given twice (first on line " + std::to_string(r.hardware.line) + ")");
        r.hardware = {h, line};
    } else {
        unknownKeyword(a, kw, "require", {"version", "precision", "backend", "max_value", "hardware"});
        return;
    }
    a.end();
}

void Parser::renderTargetLine(Args& a, std::string_view kw) {
    RenderTargetDesc& rt = m_file.renderTarget;
    uint32_t line = a.line();
    if (iequals(kw, "size")) {
        std::optional<int64_t> w = a.integer("render target width", 1, kMaxTextureSide);
        std::optional<int64_t> h = a.integer("render target height", 1, kMaxTextureSide);
        if (w && h) rt.size = {{uint32_t(*w), uint32_t(*h)}, line};
    } else if (iequals(kw, "format")) {
        assign(rt.format, a.name(kRenderTargetFormatNames, "render target format"), line);
    } else if (iequals(kw, "clear")) {
        assign(rt.clear, a.color("clear colour"), line);
    } else if (iequals(kw, "depth")) {
        std::optional<bool> on = a.name(kOnOff, "depth buffer");
        if (on && *on && !a.atEnd()) {
            std::optional<float> z = a.floatValue("depth clear value");
            if (z && (*z < 0 || *z > 1))
                a.error("depth clear value must be in [0, 1]");
            else if (z)
                rt.depthClear = *z;
        }
        assign(rt.depth, on, line);
    } else {
        unknownKeyword(a, kw, "render target", {"size", "format", "clear", "depth"});
        return;
    }
    a.end();
}

std::optional<TextureArg> Parser::textureArg(Args& a, bool resultArg) {
    TextureArg arg;
    if (a.peekNumeric()) {
        // Any DWORD SetTextureStageState takes: D3DTA_SELECTMASK, COMPLEMENT, ALPHAREPLICATE.
        std::optional<uint32_t> w = a.word("argument word");
        if (!w) return std::nullopt;
        arg.source = ArgSource(*w & 0xf);
        arg.complement = (*w & 0x10) != 0;
        arg.alphaReplicate = (*w & 0x20) != 0;
        arg.otherBits = *w & ~0x3fu;
        return arg;
    }
    if (resultArg) {
        if (!a.need("result (current or temp)")) return std::nullopt;
        std::string_view t = a.next();
        if (iequals(t, "current"))
            arg.source = ArgSource::Current;
        else if (iequals(t, "temp"))
            arg.source = ArgSource::Temp;
        else {
            a.error("unknown result argument " + quote(t) + " (expected current or temp)");
            return std::nullopt;
        }
        return arg;
    }
    std::optional<ArgSource> src = a.name(kArgSources, "argument");
    if (!src) return std::nullopt;
    arg.source = *src;
    while (!a.atEnd()) {
        std::string_view m = a.next();
        bool* flag = iequals(m, "complement")       ? &arg.complement
                     : iequals(m, "alphareplicate") ? &arg.alphaReplicate
                                                    : nullptr;
        if (!flag) {
            a.error("unknown argument modifier " + quote(m) + " (expected complement or alphareplicate)");
            return std::nullopt;
        }
        if (*flag) a.error("modifier " + quote(m) + " given twice");
        *flag = true;
    }
    return arg;
}

void Parser::stageLine(Args& a, std::string_view kw) {
    StageDesc& s = m_file.stages[m_index];
    uint32_t line = a.line();
    struct ArgKeyword {
        const char* name;
        Setting<TextureArg> StageDesc::*member;
    };
    static const ArgKeyword kArgs[] = {
        {"colorarg0", &StageDesc::colorArg0}, {"colorarg1", &StageDesc::colorArg1},
        {"colorarg2", &StageDesc::colorArg2}, {"alphaarg0", &StageDesc::alphaArg0},
        {"alphaarg1", &StageDesc::alphaArg1}, {"alphaarg2", &StageDesc::alphaArg2},
        {"resultarg", &StageDesc::resultArg},
    };
    for (const ArgKeyword& k : kArgs) {
        if (iequals(kw, k.name)) {
            assign(s.*k.member, textureArg(a, k.member == &StageDesc::resultArg), line);
            a.end();
            return;
        }
    }
    if (iequals(kw, "bumpenvmat")) {
        Vec4 m{};
        if (a.floats(m.data(), 4, "bumpenvmat (MAT00 MAT01 MAT10 MAT11)")) s.bumpEnvMat = {m, line};
    } else if (iequals(kw, "lscale")) {
        assign(s.lScale, a.floatValue("lscale"), line);
    } else if (iequals(kw, "loffset")) {
        assign(s.lOffset, a.floatValue("loffset"), line);
    } else if (iequals(kw, "transform")) {
        // D3DTTFF_*: SetTextureStageState takes any DWORD, so a raw word is accepted too.
        const std::string what = "transform flags (disable, count1 ... count4 [projected], projected, or a word)";
        if (!a.need(what)) return;
        std::string_view f = a.next();
        TransformFlags flags;
        if (iequals(f, "disable")) {
            flags.bits = 0;
        } else if (iequals(f, "projected")) {
            flags.bits = 256;  // D3DTTFF_PROJECTED alone (count 0)
        } else if (f.size() == 6 && iequals(f.substr(0, 5), "count") && f[5] >= '1' && f[5] <= '4') {
            flags.bits = uint32_t(f[5] - '0');
            if (a.peekIs("projected")) {
                a.next();
                flags.bits |= 256;
            }
        } else if (std::optional<uint32_t> w = parseWord(f)) {
            flags.bits = *w;
        } else {
            a.error("unknown transform flags " + quote(f) + " (expected " + what.substr(17));
            return;
        }
        s.transformFlags = {flags, line};
    } else if (iequals(kw, "texcoordindex")) {
        // The set (low word) and any D3DTSS_TCI_* mode (high word), as SetTextureStageState takes.
        std::optional<uint32_t> n = a.word("texcoordindex");
        if (n) s.texCoordIndex = {*n, line};
    } else if (iequals(kw, "colorop") || iequals(kw, "alphaop")) {
        std::optional<TextureOp> op;
        if (a.peekNumeric()) {
            if (std::optional<uint32_t> w = a.word("texture op")) op = TextureOp(*w);
        } else {
            op = a.name(kTextureOps, "texture op");
        }
        assign(iequals(kw, "colorop") ? s.colorOp : s.alphaOp, op, line);
    } else {
        unknownKeyword(a, kw, "stage",
                       {"bumpenvmat", "lscale", "loffset", "transform", "texcoordindex", "colorop", "colorarg0",
                        "colorarg1", "colorarg2", "alphaop", "alphaarg0", "alphaarg1", "alphaarg2", "resultarg"},
                       "bumpenvmat, lscale, loffset, transform, texcoordindex, colorop, colorarg0-2, alphaop, "
                       "alphaarg0-2 or resultarg");
        return;
    }
    a.end();
}

void Parser::renderStateLine(Args& a, std::string_view kw) {
    RenderStateDesc& rs = m_file.renderState;
    uint32_t line = a.line();
    if (iequals(kw, "alphablend")) {
        assign(rs.alphaBlend, a.name(kOnOff, "alphablend"), line);
    } else if (iequals(kw, "srcblend")) {
        assign(rs.srcBlend, a.name(kBlends, "blend factor"), line);
    } else if (iequals(kw, "destblend")) {
        assign(rs.destBlend, a.name(kBlends, "blend factor"), line);
    } else if (iequals(kw, "blendop")) {
        assign(rs.blendOp, a.name(kBlendOps, "blend op"), line);
    } else if (iequals(kw, "blendfactor")) {
        assign(rs.blendFactor, a.color("blend factor colour"), line);
    } else if (iequals(kw, "alphatest")) {
        std::optional<bool> on = a.name(kOnOff, "alphatest");
        if (on && *on) {
            std::optional<CompareFunc> f = a.name(kCompareFuncs, "alpha compare function");
            std::optional<int64_t> ref = a.integer("alpha reference", 0, 255);
            if (!f || !ref) return;
            rs.alphaFunc = {*f, line};
            rs.alphaRef = {uint32_t(*ref), line};
        }
        assign(rs.alphaTest, on, line);
    } else if (iequals(kw, "texturefactor")) {
        assign(rs.textureFactor, a.color("texture factor"), line);
    } else if (iequals(kw, "fog")) {
        std::optional<bool> on = a.name(kOnOff, "fog");
        if (on && *on && !a.atEnd()) assign(rs.fogColor, a.color("fog colour"), line);
        assign(rs.fog, on, line);
    } else if (iequals(kw, "zfunc")) {
        assign(rs.zFunc, a.name(kCompareFuncs, "depth compare function"), line);
    } else if (iequals(kw, "zwrite")) {
        assign(rs.zWrite, a.name(kOnOff, "zwrite"), line);
    } else if (iequals(kw, "cullmode")) {
        assign(rs.cullMode, a.name(kCullModes, "cull mode"), line);
    } else if (iequals(kw, "colorwrite")) {
        if (!a.need("colour write channels (any of r g b a, or none)")) return;
        uint8_t mask = 0;
        bool ok = true;
        if (a.peekIs("none")) {
            a.next();
        } else {
            while (ok && !a.atEnd()) {
                std::string_view t = a.next();
                for (char c : t) {
                    char l = lowerChar(c);
                    uint8_t bit = l == 'r' ? kWriteR : l == 'g' ? kWriteG : l == 'b' ? kWriteB : l == 'a' ? kWriteA : 0;
                    if (!bit || (mask & bit)) {
                        a.error("bad colour write channels " + quote(t) + " (any of r g b a, each once, or none)");
                        ok = false;
                        break;
                    }
                    mask |= bit;
                }
            }
        }
        if (ok) rs.colorWrite = {mask, line};
    } else {
        unknownKeyword(a, kw, "render state",
                       {"alphablend", "srcblend", "destblend", "blendop", "blendfactor", "alphatest", "texturefactor",
                        "fog", "zfunc", "zwrite", "cullmode", "colorwrite"});
        return;
    }
    a.end();
}

void Parser::transformLine(Args& a, std::string_view kw) {
    TransformDesc& t = m_file.transform;
    uint32_t line = a.line();
    Setting<Matrix4>* target = nullptr;
    if (iequals(kw, "world"))
        target = &t.world;
    else if (iequals(kw, "view"))
        target = &t.view;
    else if (iequals(kw, "projection"))
        target = &t.projection;
    else if (kw.size() == 8 && iequals(kw.substr(0, 7), "texture") && kw[7] >= '0' && kw[7] <= '7')
        target = &t.texture[size_t(kw[7] - '0')];
    if (target) {
        Matrix4 m{};
        if (a.floats(m.data(), 16, std::string(kw) + " matrix (16 floats)")) *target = {m, line};
    } else if (iequals(kw, "viewport")) {
        Viewport vp;
        std::optional<int64_t> x = a.integer("viewport x", 0, kMaxTextureSide);
        std::optional<int64_t> y = a.integer("viewport y", 0, kMaxTextureSide);
        std::optional<int64_t> w = a.integer("viewport width", 1, kMaxTextureSide);
        std::optional<int64_t> h = a.integer("viewport height", 1, kMaxTextureSide);
        if (!x || !y || !w || !h) return;
        vp.x = uint32_t(*x);
        vp.y = uint32_t(*y);
        vp.width = uint32_t(*w);
        vp.height = uint32_t(*h);
        if (!a.atEnd()) {
            std::optional<float> zn = a.floatValue("viewport minz"), zf = a.floatValue("viewport maxz");
            if (!zn || !zf) return;
            if (*zn < 0 || *zf > 1 || *zn > *zf) {
                a.error("viewport depth range must satisfy 0 <= minz <= maxz <= 1");
                return;
            }
            vp.minZ = *zn;
            vp.maxZ = *zf;
        }
        t.viewport = {vp, line};
    } else {
        unknownKeyword(a, kw, "transform",
                       {"world", "view", "projection", "texture0", "texture1", "texture2", "texture3", "texture4",
                        "texture5", "texture6", "texture7", "viewport"},
                       "world, view, projection, texture0 ... texture7 or viewport");
        return;
    }
    a.end();
}

void Parser::constantsLine(Args& a, std::string_view kw) {
    std::optional<int> n = registerIndex(kw, 'c');
    if (!n || *n > 7) {
        a.error("unknown keyword " + quote(kw) + " in [constants] (expected c0 ... c7)");
        return;
    }
    for (const ConstantDesc& c : m_file.constants)
        if (c.index == *n) {
            a.error("c" + std::to_string(*n) + " set twice (first at line " + std::to_string(c.line) + ")");
            return;
        }
    ConstantDesc c;
    c.line = a.line();
    c.index = *n;
    if (!a.floats(c.value.data(), 4, "c" + std::to_string(*n) + " (4 floats)")) return;
    a.end();
    m_file.constants.push_back(c);
}

}  // namespace testfile_detail

using testfile_detail::kPrecisions;
using testfile_detail::kTextureOps;
using testfile_detail::Parser;

const char* backendName(Backend b) { return b == Backend::Gl ? "gl" : "emu"; }

const char* precisionName(Precision p) {
    for (const auto& e : kPrecisions)
        if (e.value == p) return e.name;
    return "?";
}

const char* textureOpName(TextureOp op) {
    for (const auto& e : kTextureOps)
        if (e.value == op) return e.name;
    return "?";
}

Color Color::fromArgb(uint32_t argb) {
    Color c;
    c.packed = true;
    c.argb = argb;
    c.rgba = {float((argb >> 16) & 0xff) / 255.0f, float((argb >> 8) & 0xff) / 255.0f, float(argb & 0xff) / 255.0f,
              float(argb >> 24) / 255.0f};
    return c;
}

Color Color::fromFloats(const Vec4& rgba) {
    Color c;
    c.packed = false;
    c.rgba = rgba;
    auto level = [](float v) { return uint32_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
    c.argb = (level(rgba[3]) << 24) | (level(rgba[0]) << 16) | (level(rgba[1]) << 8) | level(rgba[2]);
    return c;
}

StageDesc defaultStage(int stage) {
    // D3D9 defaults (IDirect3DDevice9::SetTextureStageState): stage 0 modulates texture by
    // diffuse and selects texture alpha, every other stage is disabled.
    StageDesc s;
    s.stage = stage;
    s.colorOp.value = stage == 0 ? TextureOp::Modulate : TextureOp::Disable;
    s.alphaOp.value = stage == 0 ? TextureOp::SelectArg1 : TextureOp::Disable;
    s.colorArg1.value = {ArgSource::Texture, false, false};
    s.colorArg2.value = {ArgSource::Current, false, false};
    s.alphaArg1.value = {ArgSource::Texture, false, false};
    s.alphaArg2.value = {ArgSource::Current, false, false};
    s.colorArg0.value = s.alphaArg0.value = s.resultArg.value = {ArgSource::Current, false, false};
    s.texCoordIndex.value = uint32_t(stage);
    return s;
}

Matrix4 identityMatrix() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

std::string PixelShaderBlock::textWithFileLines() const {
    return std::string(firstLine > 1 ? firstLine - 1 : 0, '\n') + text;
}

const TextureDesc* TestFile::texture(int stage) const {
    for (const TextureDesc& t : textures)
        if (t.stage == stage) return &t;
    return nullptr;
}

const SamplerDesc* TestFile::sampler(int stage) const {
    for (const SamplerDesc& s : samplers)
        if (s.stage == stage) return &s;
    return nullptr;
}

const StageDesc* TestFile::stage(int stage) const {
    for (const StageDesc& s : stages)
        if (s.stage == stage) return &s;
    return nullptr;
}

bool parseTestFile(std::string_view text, const std::string& fileName, TestFile& out,
                   std::vector<TestFileError>& errors) {
    size_t before = errors.size();
    out = TestFile{};
    out.fileName = fileName;
    Parser(out, errors).run(text);
    // Whole-file checks run last; report everything in file order.
    std::stable_sort(errors.begin() + std::ptrdiff_t(before), errors.end(),
                     [](const TestFileError& a, const TestFileError& b) { return a.line < b.line; });
    return errors.size() == before;
}

std::string formatTestFileError(const std::string& fileName, const TestFileError& error) {
    if (error.line == 0) return fileName + ": " + error.message;
    return fileName + ":" + std::to_string(error.line) + ": " + error.message;
}

}  // namespace ps11
