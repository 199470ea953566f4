// Unit tests of the .ps11test reader (ps11/testfile.h): every section and command into the
// data model, and every error path with its line number.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "ps11/testfile.h"

using namespace ps11;

namespace {

struct Parsed {
    TestFile file;
    std::vector<TestFileError> errors;
    bool ok = false;
};

Parsed parse(std::string_view text) {
    Parsed p;
    p.ok = parseTestFile(text, "t.ps11test", p.file, p.errors);
    return p;
}

std::string dump(const Parsed& p) {
    std::string s;
    for (const TestFileError& e : p.errors) s += formatTestFileError("t.ps11test", e) + "\n";
    return s;
}

// True if an error on `line` contains `fragment`.
bool hasError(const Parsed& p, uint32_t line, std::string_view fragment) {
    for (const TestFileError& e : p.errors)
        if (e.line == line && e.message.find(fragment) != std::string::npos) return true;
    return false;
}

#define REQUIRE_OK(p) \
    INFO(dump(p));    \
    REQUIRE((p).ok)

#define CHECK_ERROR(p, line, fragment)      \
    do {                                    \
        INFO(dump(p));                      \
        CHECK(!(p).ok);                     \
        CHECK(hasError(p, line, fragment)); \
    } while (0)

template <class T>
const T& op(const TestFile& f, size_t i) {
    REQUIRE(i < f.commands.size());
    REQUIRE(std::holds_alternative<T>(f.commands[i].op));
    return std::get<T>(f.commands[i].op);
}

}  // namespace

TEST_CASE("testfile: empty input and comments", "[testfile]") {
    Parsed p = parse("");
    REQUIRE_OK(p);
    CHECK(!p.file.pixelShader.present());
    CHECK(p.file.commands.empty());
    CHECK(p.file.renderTarget.size.value == std::array<uint32_t, 2>{64, 64});
    CHECK(p.file.renderTarget.format.value == TexFormat::A8R8G8B8);
    CHECK(p.file.renderTarget.clear.value.argb == 0);

    Parsed q = parse("% just a comment\n\n   \n%[texture 0]\n");
    REQUIRE_OK(q);
}

TEST_CASE("testfile: [require]", "[testfile]") {
    Parsed p = parse("[REQUIRE]\nVersion PS_1_4\nprecision fx12\nbackend gl\nmax_value 8\n");
    REQUIRE_OK(p);
    const RequireDesc& r = p.file.require;
    CHECK(r.line == 1);
    CHECK(r.versionMinor.value == 4);
    CHECK(r.versionMinor.line == 2);
    CHECK(r.precision.value == Precision::Fx12);
    CHECK(r.backends.value == kBackendGl);
    CHECK(r.maxValue.value == 8.0f);

    Parsed both = parse("[require]\nbackend emu, gl\n");
    REQUIRE_OK(both);
    CHECK(both.file.require.backends.value == (kBackendEmu | kBackendGl));

    Parsed d = parse("[require]\n");
    REQUIRE_OK(d);
    CHECK(d.file.require.precision.value == Precision::Fx8);
    CHECK(!d.file.require.precision.isSet());
    CHECK(d.file.require.backends.value == kAllBackends);

    CHECK_ERROR(parse("[require]\nversion ps_2_0\n"), 2, "unknown shader version");
    CHECK_ERROR(parse("[require]\nversion\n"), 2, "missing shader version");
    CHECK_ERROR(parse("[require]\nprecision fx16\n"), 2, "unknown precision 'fx16'");
    CHECK_ERROR(parse("[require]\nbackend d3d\n"), 2, "unknown backend 'd3d'");
    CHECK_ERROR(parse("[require]\nbackend\n"), 2, "missing backend");
    CHECK_ERROR(parse("[require]\nmax_value 0\n"), 2, "max_value must be > 0");
    CHECK_ERROR(parse("[require]\nmax_value x\n"), 2, "bad number 'x'");
    CHECK_ERROR(parse("[require]\nshader ps_1_1\n"), 2, "unknown keyword 'shader' in [require]");
    CHECK_ERROR(parse("[require]\nversion ps_1_1 ps_1_2\n"), 2, "unexpected 'ps_1_2'");
}

TEST_CASE("testfile: [render target]", "[testfile]") {
    Parsed p = parse("[render target]\nsize 640 480\nformat a16b16g16r16f\nclear 0.5 0.25 1 1\ndepth on 0.5\n");
    REQUIRE_OK(p);
    const RenderTargetDesc& rt = p.file.renderTarget;
    CHECK(rt.size.value == std::array<uint32_t, 2>{640, 480});
    CHECK(rt.size.line == 2);
    CHECK(rt.format.value == TexFormat::A16B16G16R16F);
    CHECK(!rt.clear.value.packed);
    CHECK(rt.clear.value.rgba == Vec4{0.5f, 0.25f, 1, 1});
    CHECK(rt.depth.value);
    CHECK(rt.depthClear == 0.5f);

    Parsed h = parse("[render target]\nclear 0xff000080\ndepth off\n");
    REQUIRE_OK(h);
    CHECK(h.file.renderTarget.clear.value.packed);
    CHECK(h.file.renderTarget.clear.value.argb == 0xff000080u);
    CHECK(h.file.renderTarget.clear.value.rgba[2] == Approx(128 / 255.0));
    CHECK(h.file.renderTarget.clear.value.rgba[3] == 1.0f);
    CHECK(!h.file.renderTarget.depth.value);
    CHECK(h.file.renderTarget.depth.isSet());

    CHECK_ERROR(parse("[render target]\nsize 0 4\n"), 2, "out of range");
    CHECK_ERROR(parse("[render target]\nsize 100000 4\n"), 2, "out of range");
    CHECK_ERROR(parse("[render target]\nsize 4\n"), 2, "missing render target height");
    CHECK_ERROR(parse("[render target]\nsize 4.5 4\n"), 2, "must be an integer");
    CHECK_ERROR(parse("[render target]\nformat L8\n"), 2, "unknown render target format 'L8'");
    // Every render-target format of the format rows, and only those, names a target.
    for (const FormatRow& row : kFormatRows) {
        if (!row.texture) continue;
        Parsed f = parse(std::string("[render target]\nformat ") + row.name + "\n");
        CHECK(f.errors.empty() == row.renderTarget);
        if (row.renderTarget) CHECK(f.file.renderTarget.format.value == row.texFormat);
    }
    CHECK_ERROR(parse("[render target]\nclear 0 0\n"), 2, "one 0xAARRGGBB word or 4 floats");
    CHECK_ERROR(parse("[render target]\nclear red\n"), 2, "bad clear colour 'red'");
    CHECK_ERROR(parse("[render target]\nclear 0x1ffffffff\n"), 2, "bad clear colour");
    CHECK_ERROR(parse("[render target]\ndepth on 2\n"), 2, "depth clear value must be in [0, 1]");
    CHECK_ERROR(parse("[render target]\ndepth maybe\n"), 2, "unknown depth buffer 'maybe'");
    CHECK_ERROR(parse("[render target]\nsamples 4\n"), 2, "unknown keyword 'samples'");
}

TEST_CASE("testfile: [texture N] rows, levels, fill", "[testfile]") {
    Parsed p = parse(
        "[texture 3]\n"
        "size 4 2\n"
        "format A8R8G8B8\n"
        "levels 2\n"
        "level 0\n"
        "0xff0000ff 0xff00ff00 1 2\n"
        "0xffff0000 0xffffffff 3 4\n"
        "level 1\n"
        "fill 0x80808080\n");
    REQUIRE_OK(p);
    REQUIRE(p.file.textures.size() == 1);
    const TextureDesc& t = p.file.textures[0];
    CHECK(t.line == 1);
    CHECK(t.stage == 3);
    CHECK(p.file.texture(3) == &t);
    CHECK(p.file.texture(0) == nullptr);
    CHECK(t.width == 4);
    CHECK(t.height == 2);
    CHECK(!t.isVolume());
    CHECK(t.levels.value == 2);
    REQUIRE(t.data.size() == 2);
    CHECK(t.data[0].line == 5);
    CHECK(t.data[0].width == 4);
    CHECK(t.data[0].height == 2);
    REQUIRE(t.data[0].texels.size() == 8);
    CHECK(t.data[0].texels[0].bits == 0xff0000ffu);
    CHECK(t.data[0].texels[3].bits == 2u);
    CHECK(t.data[0].texels[4].bits == 0xffff0000u);
    CHECK(t.data[1].level == 1);
    CHECK(t.data[1].width == 2);
    CHECK(t.data[1].height == 1);
    CHECK(t.data[1].hasFill);
    CHECK(t.data[1].fill.bits == 0x80808080u);
    CHECK(t.data[1].texels.empty());
}

TEST_CASE("testfile: texture formats, float texels and volumes", "[testfile]") {
    Parsed p = parse(
        "[texture 0]\nsize 2 1 2\nformat A32B32G32R32F\nlevel 0\n(0.5 0.25 0 1) (1)\n(2 3) ( -1 0 0 )\n"
        "[texture 1]\nsize 2 1\nformat v8u8\nlevel 0\n0x7f81 0xffff\n"
        "[texture 2]\nsize 1 1\nformat R32F\nfill (0.125)\n"
        "[texture 3]\nsize 8 8\nlevels 0\nlevel 0\nfill 0xff00ff00\n");
    REQUIRE_OK(p);
    const TextureDesc& vol = *p.file.texture(0);
    CHECK(vol.isVolume());
    CHECK(vol.depth == 2);
    REQUIRE(vol.data[0].texels.size() == 4);
    CHECK(vol.data[0].texels[0].count == 4);
    CHECK(vol.data[0].texels[0].value == Vec4{0.5f, 0.25f, 0, 1});
    CHECK(vol.data[0].texels[1].count == 1);
    CHECK(vol.data[0].texels[1].value == Vec4{1, 0, 0, 1});
    CHECK(vol.data[0].texels[2].value == Vec4{2, 3, 0, 1});
    CHECK(vol.data[0].texels[3].value == Vec4{-1, 0, 0, 1});
    CHECK(p.file.texture(1)->format.value == TexFormat::V8U8);
    CHECK(p.file.texture(1)->data[0].texels[0].bits == 0x7f81u);
    CHECK(p.file.texture(2)->data[0].hasFill);
    CHECK(p.file.texture(2)->data[0].fill.value[0] == 0.125f);
    CHECK(p.file.texture(3)->levels.value == 0);
    CHECK(p.file.texture(3)->levels.isSet());

    for (const char* fmt : {"A8R8G8B8", "X8R8G8B8", "A8", "L8", "A8L8", "V8U8", "L6V5U5", "X8L8V8U8", "Q8W8V8U8",
                            "V16U16", "A16B16G16R16F", "A32B32G32R32F", "R32F"}) {
        bool isFloat = std::string(fmt).back() == 'F';
        std::string text =
            std::string("[texture 0]\nsize 1 1\nformat ") + fmt + "\nfill " + (isFloat ? "(1)" : "0") + "\n";
        Parsed f = parse(text);
        INFO(fmt);
        REQUIRE_OK(f);
        CHECK(texFormatName(f.file.texture(0)->format.value) == std::string(fmt));
    }
}

TEST_CASE("testfile: texture errors", "[testfile]") {
    CHECK_ERROR(parse("[texture 8]\n"), 1, "out of range (0 to 7)");
    CHECK_ERROR(parse("[texture]\n"), 1, "missing [texture N] texture stage");
    CHECK_ERROR(parse("[texture x]\n"), 1, "bad number 'x'");
    CHECK_ERROR(parse("[texture 0]\nsize 2 2\nfill 0\n[texture 0]\nsize 1 1\nfill 0\n"), 4,
                "duplicate section [texture 0] (first at line 1)");
    CHECK_ERROR(parse("[texture 0]\nformat A8R8G8B8\n"), 1, "[texture 0] needs a 'size'");
    CHECK_ERROR(parse("[texture 0]\nsize 2 2\n"), 1, "no data for level 0");
    CHECK_ERROR(parse("[texture 0]\nsize 20000 1\nfill 0\n"), 2, "out of range");
    CHECK_ERROR(parse("[texture 0]\nsize 16384 16384 2\nfill 0\n"), 2, "texture is too large");
    CHECK_ERROR(parse("[texture 0]\nsize 4 4 4096\nfill 0\n"), 2, "volume texture depth '4096' is out of range");
    CHECK_ERROR(parse("[texture 0]\nsize 0 1\n"), 2, "texture width '0' is out of range");
    CHECK_ERROR(parse("[texture 0]\nsize 2048 2048 2048\nfill 0\n"), 2, "texture is too large");
    CHECK_ERROR(parse("[texture 0]\nsize -2 2\n"), 2, "out of range");
    CHECK_ERROR(parse("[texture 0]\nsize 2 2\nformat D24S8\nfill 0\n"), 3, "unknown texture format 'D24S8'");
    CHECK_ERROR(parse("[texture 0]\nsize 2 2\nlevel 0\n0 0\n"), 3, "level 0 has 1 texel rows, expected 2");
    CHECK_ERROR(parse("[texture 0]\nsize 2 2\nlevel 0\n0 0\n0 0\n0 0\n"), 3, "level 0 has 3 texel rows");
    CHECK_ERROR(parse("[texture 0]\nsize 2 1 2\nlevel 0\n0 0\n"), 3, "(height x depth, slice after slice)");
    CHECK_ERROR(parse("[texture 0]\nsize 2 2\nlevel 0\n0 0 0\n0 0\n"), 4, "texel row has 3 texels, level 0 is 2 wide");
    CHECK_ERROR(parse("[texture 0]\nsize 2 2\nlevel 0\n0\n0 0\n"), 4, "texel row has 1 texels");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\n0\n"), 3, "texel row outside a level");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nlevel 0\nfill 0\n0\n"), 5, "texel row after 'fill'");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nlevel 0\n0\nfill 0\n"), 5, "'fill' after texel rows");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nlevel 0\n0\nlevel 0\n0\n"), 5, "level 0 given twice (first at line 3)");
    CHECK_ERROR(parse("[texture 0]\nsize 4 4\nlevel 1\nfill 0\n"), 3, "level 1 is beyond the texture's 1 level");
    CHECK_ERROR(parse("[texture 0]\nsize 4 4\nlevels 0\nlevel 1\nfill 0\n"), 4, "levels 0 builds the chain");
    CHECK_ERROR(parse("[texture 0]\nsize 4 4\nlevels 4\nlevel 0\nfill 0\n"), 3, "levels 4 is more than a 4x4 texture");
    CHECK_ERROR(parse("[texture 0]\nsize 4 4\nlevels 2\nlevel 0\nfill 0\n"), 1, "no data for level 1");
    CHECK_ERROR(parse("[texture 0]\nlevel 0\n"), 2, "'level' needs the texture's 'size' first");
    CHECK_ERROR(parse("[texture 0]\nfill 0\n"), 2, "'fill' needs the texture's 'size' first");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nfill 0\nsize 2 2\n"), 4, "'size' must come before the texel data");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nfill 0\nformat A8\n"), 4, "'format' must come before");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nfill 0\nlevels 1\n"), 4, "'levels' must come before");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nfill 0\nfill 0\n"), 4, "'fill' after texel rows or another 'fill'");
    CHECK_ERROR(parse("[texture 0]\nsize 2 1\nformat A8\nlevel 0\n0xff 0x100\n"), 5,
                "texel 0x100 does not fit format A8 (8 bits)");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nformat V8U8\nfill 0x10000\n"), 4, "does not fit format V8U8 (16 bits)");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nformat R32F\nfill 0\n"), 4, "takes float texels in parentheses");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nformat R32F\nfill (1 2)\n"), 4, "R32F takes one float per texel");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nfill (1 2)\n"), 3, "takes one hex word per texel");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nformat A32B32G32R32F\nlevel 0\n(1 2 3 4 5)\n"), 5, "at most 4 floats");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nformat A32B32G32R32F\nlevel 0\n(1 2\n"), 5, "missing ')'");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nformat A32B32G32R32F\nlevel 0\n()\n"), 5, "empty texel '()'");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nlevel 0\n0xfffffffff\n"), 4, "bad texel '0xfffffffff'");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nlevel 0\n1.5\n"), 4, "bad texel '1.5'");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nlevel 0\n0x12g4\n"), 4, "bad texel '0x12g4'");
    CHECK_ERROR(parse("[texture 0]\nsize 1 1\nmipmaps 1\nfill 0\n"), 3, "unknown keyword 'mipmaps' in [texture]");
}

TEST_CASE("testfile: [sampler N]", "[testfile]") {
    Parsed p = parse(
        "[sampler 2]\nfilter linear mip point\naddress clamp wrap mirror\nborder 0xff00ff00\n"
        "[sampler 3]\nfilter point linear\naddress border\nborder 0 0.5 1 1\n");
    REQUIRE_OK(p);
    const SamplerDesc& s = *p.file.sampler(2);
    CHECK(s.line == 1);
    CHECK(s.minFilter.value == Filter::Linear);
    CHECK(s.magFilter.value == Filter::Linear);
    CHECK(s.mipFilter.value == Filter::Point);
    CHECK(s.addressU.value == TextureAddress::Clamp);
    CHECK(s.addressV.value == TextureAddress::Wrap);
    CHECK(s.addressW.value == TextureAddress::Mirror);
    CHECK(s.border.value.argb == 0xff00ff00u);
    const SamplerDesc& t = *p.file.sampler(3);
    CHECK(t.minFilter.value == Filter::Point);
    CHECK(t.magFilter.value == Filter::Linear);
    CHECK(!t.mipFilter.isSet());
    CHECK(t.mipFilter.value == Filter::None);
    CHECK(t.addressU.value == TextureAddress::Border);
    CHECK(t.addressV.value == TextureAddress::Border);
    CHECK(t.addressW.value == TextureAddress::Border);
    CHECK(t.border.value.rgba == Vec4{0, 0.5f, 1, 1});
    CHECK(p.file.sampler(0) == nullptr);

    CHECK_ERROR(parse("[sampler 0]\nfilter anisotropic\n"), 2, "unknown filter 'anisotropic'");
    CHECK_ERROR(parse("[sampler 0]\nfilter linear mip cubic\n"), 2, "unknown mip filter 'cubic'");
    CHECK_ERROR(parse("[sampler 0]\nfilter linear mip\n"), 2, "missing mip filter");
    CHECK_ERROR(parse("[sampler 0]\naddress clamp clamp clamp clamp\n"), 2, "unexpected 'clamp'");
    CHECK_ERROR(parse("[sampler 0]\naddress mirrortwice\n"), 2, "unknown address mode 'mirrortwice'");
    Parsed once = parse("[sampler 0]\naddress mirroronce clamp\n");  // every D3DTADDRESS_* value
    REQUIRE_OK(once);
    CHECK(once.file.sampler(0)->addressU.value == TextureAddress::MirrorOnce);
    CHECK(once.file.sampler(0)->addressV.value == TextureAddress::Clamp);
    CHECK_ERROR(parse("[sampler 0]\nborder\n"), 2, "missing border colour");
    CHECK_ERROR(parse("[sampler 0]\nlodbias 1\n"), 2, "unknown keyword 'lodbias' in [sampler]");
    CHECK_ERROR(parse("[sampler 1]\n[sampler 1]\n"), 2, "duplicate section [sampler 1]");
}

TEST_CASE("testfile: [stage N]", "[testfile]") {
    Parsed p = parse(
        "[stage 1]\n"
        "bumpenvmat 0.5 0 0 0.5\n"
        "lscale 2\n"
        "loffset -0.5\n"
        "transform count3 projected\n"
        "texcoordindex 0\n"
        "colorop BumpEnvMap\n"
        "colorarg0 temp\n"
        "colorarg1 texture complement alphareplicate\n"
        "colorarg2 diffuse\n"
        "alphaop modulatealpha_addcolor\n"
        "alphaarg0 specular\n"
        "alphaarg1 tfactor complement\n"
        "alphaarg2 current alphareplicate\n"
        "resultarg temp\n");
    REQUIRE_OK(p);
    const StageDesc& s = *p.file.stage(1);
    CHECK(s.bumpEnvMat.value == Vec4{0.5f, 0, 0, 0.5f});
    CHECK(s.lScale.value == 2.0f);
    CHECK(s.lOffset.value == -0.5f);
    CHECK(s.transformFlags.value == TransformFlags{3 | 256});
    CHECK(s.texCoordIndex.value == 0);
    CHECK(s.colorOp.value == TextureOp::BumpEnvMap);
    CHECK(s.colorOp.line == 7);
    CHECK(s.colorArg0.value == TextureArg{ArgSource::Temp, false, false});
    CHECK(s.colorArg1.value == TextureArg{ArgSource::Texture, true, true});
    CHECK(s.colorArg2.value == TextureArg{ArgSource::Diffuse, false, false});
    CHECK(s.alphaOp.value == TextureOp::ModulateAlphaAddColor);
    CHECK(s.alphaArg0.value.source == ArgSource::Specular);
    CHECK(s.alphaArg1.value == TextureArg{ArgSource::TFactor, true, false});
    CHECK(s.alphaArg2.value == TextureArg{ArgSource::Current, false, true});
    CHECK(s.resultArg.value.source == ArgSource::Temp);

    // Defaults are D3D9's: stage 0 modulates, the others are disabled; texcoordindex = stage.
    Parsed d = parse("[stage 0]\n[stage 5]\ntransform disable\n");
    REQUIRE_OK(d);
    CHECK(d.file.stage(0)->colorOp.value == TextureOp::Modulate);
    CHECK(d.file.stage(0)->alphaOp.value == TextureOp::SelectArg1);
    CHECK(!d.file.stage(0)->colorOp.isSet());
    CHECK(d.file.stage(5)->colorOp.value == TextureOp::Disable);
    CHECK(d.file.stage(5)->texCoordIndex.value == 5);
    CHECK(d.file.stage(5)->transformFlags.value == TransformFlags{0});
    CHECK(d.file.stage(5)->transformFlags.isSet());

    // Every value SetTextureStageState takes can be written: PROJECTED alone, any transform
    // word, texture ops, arguments and texcoordindex as numbers (high-word TCI modes too).
    Parsed w = parse(
        "[stage 2]\ntransform projected\n[stage 3]\ntransform 0xffffffff\ncolorop 99\nalphaop 0x7\n"
        "colorarg1 0x22\nalphaarg2 0xffffffff\nresultarg 5\ntexcoordindex 0x10001\n");
    REQUIRE_OK(w);
    CHECK(w.file.stage(2)->transformFlags.value == TransformFlags{256});
    const StageDesc& raw = *w.file.stage(3);
    CHECK(raw.transformFlags.value == TransformFlags{0xffffffffu});
    CHECK(uint32_t(raw.colorOp.value) == 99);
    CHECK(raw.alphaOp.value == TextureOp::Add);
    CHECK(raw.colorArg1.value == TextureArg{ArgSource::Texture, false, true});
    CHECK(raw.alphaArg2.value == TextureArg{ArgSource(15), true, true, 0xffffffc0u});
    CHECK(raw.resultArg.value.source == ArgSource::Temp);
    CHECK(raw.texCoordIndex.value == 0x10001u);
    CHECK_ERROR(parse("[stage 0]\ntransform count5\n"), 2, "unknown transform flags 'count5'");
    CHECK_ERROR(parse("[stage 0]\ncolorop 0x1ffffffff\n"), 2, "texture op");

    // [require] hardware names a class; a wrong or repeated one is an error.
    Parsed hw = parse("[require]\nhardware D3D9\n");
    REQUIRE_OK(hw);
    CHECK(hw.file.require.hardware.value == findHardware("d3d9"));
    CHECK(hw.file.require.hardware.line == 2);
    CHECK_ERROR(parse("[require]\nhardware voodoo3\n"), 2, "unknown hardware class 'voodoo3'");
    CHECK_ERROR(parse("[require]\nhardware geforce3\nhardware d3d9\n"), 3, "hardware given twice");

    const char* ops[] = {"disable",
                         "selectarg1",
                         "selectarg2",
                         "modulate",
                         "modulate2x",
                         "modulate4x",
                         "add",
                         "addsigned",
                         "addsigned2x",
                         "subtract",
                         "addsmooth",
                         "blenddiffusealpha",
                         "blendtexturealpha",
                         "blendfactoralpha",
                         "blendtexturealphapm",
                         "blendcurrentalpha",
                         "premodulate",
                         "modulatealpha_addcolor",
                         "modulatecolor_addalpha",
                         "modulateinvalpha_addcolor",
                         "modulateinvcolor_addalpha",
                         "bumpenvmap",
                         "bumpenvmapluminance",
                         "dotproduct3",
                         "multiplyadd",
                         "lerp"};
    int expected = 1;
    for (const char* name : ops) {
        Parsed o = parse(std::string("[stage 0]\ncolorop ") + name + "\nalphaop " + name + "\n");
        INFO(name);
        REQUIRE_OK(o);
        CHECK(int(o.file.stage(0)->colorOp.value) == expected);
        CHECK(int(o.file.stage(0)->alphaOp.value) == expected);
        CHECK(textureOpName(o.file.stage(0)->colorOp.value) == std::string(name));
        ++expected;
    }

    CHECK_ERROR(parse("[stage 0]\ncolorop modulate8x\n"), 2, "unknown texture op 'modulate8x'");
    CHECK_ERROR(parse("[stage 0]\ncolorarg1 constant\n"), 2, "unknown argument 'constant'");
    CHECK_ERROR(parse("[stage 0]\ncolorarg1 texture inverted\n"), 2, "unknown argument modifier 'inverted'");
    CHECK_ERROR(parse("[stage 0]\ncolorarg1 texture complement complement\n"), 2, "given twice");
    CHECK_ERROR(parse("[stage 0]\nresultarg texture\n"), 2, "unknown result argument 'texture'");
    CHECK_ERROR(parse("[stage 0]\nbumpenvmat 1 0 0\n"), 2, "missing bumpenvmat");
    CHECK_ERROR(parse("[stage 0]\nbumpenvmat 1 0 0 1 0\n"), 2, "unexpected '0'");
    CHECK_ERROR(parse("[stage 0]\ntransform count5\n"), 2, "unknown transform flags 'count5'");
    CHECK_ERROR(parse("[stage 0]\ntransform disable projected\n"), 2, "unexpected 'projected'");
    CHECK_ERROR(parse("[stage 0]\ntexcoordindex -1\n"), 2, "bad texcoordindex '-1'");
    CHECK(parse("[stage 0]\ntexcoordindex 8\n").ok);  // a set no FVF has: the draw reads (0, 0, 0, 1)
    CHECK_ERROR(parse("[stage 0]\nlscale\n"), 2, "missing lscale");
    CHECK_ERROR(parse("[stage 0]\nmagic 1\n"), 2, "unknown keyword 'magic' in [stage]");
    CHECK_ERROR(parse("[stage -1]\n"), 1, "out of range");
}

TEST_CASE("testfile: [render state]", "[testfile]") {
    Parsed p = parse(
        "[render state]\n"
        "alphablend on\n"
        "srcblend srcalpha\n"
        "destblend invsrcalpha\n"
        "blendop revsubtract\n"
        "blendfactor 0x40404040\n"
        "alphatest on greater 0x80\n"
        "texturefactor 0xff808080\n"
        "fog on 0xff102030\n"
        "zfunc greaterequal\n"
        "zwrite off\n"
        "colorwrite rga\n"
        "cullmode cw\n");
    REQUIRE_OK(p);
    const RenderStateDesc& rs = p.file.renderState;
    CHECK(rs.line == 1);
    CHECK(rs.alphaBlend.value);
    CHECK(rs.srcBlend.value == Blend::SrcAlpha);
    CHECK(rs.destBlend.value == Blend::InvSrcAlpha);
    CHECK(rs.blendOp.value == BlendOp::RevSubtract);
    CHECK(rs.blendFactor.value.argb == 0x40404040u);
    CHECK(rs.alphaTest.value);
    CHECK(rs.alphaFunc.value == CompareFunc::Greater);
    CHECK(rs.alphaRef.value == 0x80);
    CHECK(rs.textureFactor.value.argb == 0xff808080u);
    CHECK(rs.fog.value);
    CHECK(rs.fogColor.value.argb == 0xff102030u);
    CHECK(rs.zFunc.value == CompareFunc::GreaterEqual);
    CHECK(!rs.zWrite.value);
    CHECK(rs.colorWrite.value == (kWriteR | kWriteG | kWriteA));
    CHECK(rs.cullMode.value == CullMode::Cw);

    Parsed d = parse("[render state]\ncolorwrite none\nalphatest off\nfog off\nalphablend off\n");
    REQUIRE_OK(d);
    CHECK(d.file.renderState.colorWrite.value == 0);
    CHECK(!d.file.renderState.alphaTest.value);
    CHECK(d.file.renderState.alphaTest.isSet());
    Parsed def = parse("");
    CHECK(def.file.renderState.colorWrite.value == 15);
    CHECK(def.file.renderState.cullMode.value == CullMode::None);
    CHECK(def.file.renderState.zFunc.value == CompareFunc::LessEqual);

    const char* blends[] = {"zero",        "one",          "srccolor",        "invsrccolor", "srcalpha",
                            "invsrcalpha", "destalpha",    "invdestalpha",    "destcolor",   "invdestcolor",
                            "srcalphasat", "bothsrcalpha", "bothinvsrcalpha", "blendfactor", "invblendfactor"};
    int n = 1;
    for (const char* b : blends) {
        Parsed o = parse(std::string("[render state]\nsrcblend ") + b + "\ndestblend " + b + "\n");
        INFO(b);
        REQUIRE_OK(o);
        CHECK(int(o.file.renderState.srcBlend.value) == n);
        CHECK(int(o.file.renderState.destBlend.value) == n++);
    }
    n = 1;
    for (const char* b : {"add", "subtract", "revsubtract", "min", "max"}) {
        Parsed o = parse(std::string("[render state]\nblendop ") + b + "\n");
        REQUIRE_OK(o);
        CHECK(int(o.file.renderState.blendOp.value) == n++);
    }
    n = 1;
    for (const char* f : {"never", "less", "equal", "lessequal", "greater", "notequal", "greaterequal", "always"}) {
        Parsed o = parse(std::string("[render state]\nzfunc ") + f + "\nalphatest on " + f + " 1\n");
        REQUIRE_OK(o);
        CHECK(int(o.file.renderState.zFunc.value) == n);
        CHECK(int(o.file.renderState.alphaFunc.value) == n++);
    }

    CHECK_ERROR(parse("[render state]\nalphablend yes\n"), 2, "unknown alphablend 'yes' (expected on or off)");
    CHECK_ERROR(parse("[render state]\nsrcblend src\n"), 2, "unknown blend factor 'src'");
    CHECK_ERROR(parse("[render state]\nblendop mul\n"), 2, "unknown blend op 'mul'");
    CHECK_ERROR(parse("[render state]\nalphatest on greater 256\n"), 2, "alpha reference '256' is out of range");
    CHECK_ERROR(parse("[render state]\nalphatest on bigger 1\n"), 2, "unknown alpha compare function 'bigger'");
    CHECK_ERROR(parse("[render state]\nalphatest on\n"), 2, "missing alpha compare function");
    CHECK_ERROR(parse("[render state]\nzfunc\n"), 2, "missing depth compare function");
    CHECK_ERROR(parse("[render state]\ncolorwrite rgbx\n"), 2, "bad colour write channels 'rgbx'");
    CHECK_ERROR(parse("[render state]\ncolorwrite rr\n"), 2, "each once");
    CHECK_ERROR(parse("[render state]\ncullmode both\n"), 2, "unknown cull mode 'both'");
    CHECK_ERROR(parse("[render state]\ntexturefactor 1 2 3\n"), 2, "one 0xAARRGGBB word or 4 floats");
    CHECK_ERROR(parse("[render state]\nstencil on\n"), 2, "unknown keyword 'stencil' in [render state]");
    CHECK_ERROR(parse("[render state]\n[render state]\n"), 2, "duplicate section [render state]");
}

TEST_CASE("testfile: [transform] and [constants]", "[testfile]") {
    Parsed p = parse(
        "[transform]\n"
        "world 2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 1\n"
        "view 1 0 0 0  0 1 0 0  0 0 1 0  0 0 5 1\n"
        "projection 1 0 0 0  0 1 0 0  0 0 1 1  0 0 -1 0\n"
        "texture7 1 0 0 0  0 1 0 0  0 0 1 0  0.5 0.5 0 1\n"
        "viewport 8 4 32 16 0.25 0.75\n"
        "[constants]\n"
        "c0 0.5 0.5 0.5 1.0\n"
        "C7 -2 3 1e-3 0x10\n");
    REQUIRE_OK(p);
    const TransformDesc& t = p.file.transform;
    CHECK(t.world.value[0] == 2.0f);
    CHECK(t.view.value[14] == 5.0f);
    CHECK(t.projection.value[11] == 1.0f);
    CHECK(t.texture[7].value[12] == 0.5f);
    CHECK(t.texture[7].line == 5);
    CHECK(!t.texture[0].isSet());
    CHECK(t.viewport.value.x == 8);
    CHECK(t.viewport.value.y == 4);
    CHECK(t.viewport.value.width == 32);
    CHECK(t.viewport.value.height == 16);
    CHECK(t.viewport.value.minZ == 0.25f);
    CHECK(t.viewport.value.maxZ == 0.75f);
    CHECK(identityMatrix()[0] == 1.0f);
    CHECK(identityMatrix()[1] == 0.0f);
    REQUIRE(p.file.constants.size() == 2);
    CHECK(p.file.constants[0].index == 0);
    CHECK(p.file.constants[0].line == 8);
    CHECK(p.file.constants[1].index == 7);
    CHECK(p.file.constants[1].value == Vec4{-2, 3, 1e-3f, 16});

    Parsed vp = parse("[transform]\nviewport 0 0 10 10\n");
    REQUIRE_OK(vp);
    CHECK(vp.file.transform.viewport.value.maxZ == 1.0f);

    CHECK_ERROR(parse("[transform]\nworld 1 0 0 0\n"), 2, "missing world matrix (16 floats)");
    CHECK_ERROR(parse("[transform]\ntexture8 1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1\n"), 2, "unknown keyword 'texture8'");
    CHECK_ERROR(parse("[transform]\nviewport 0 0 0 10\n"), 2, "viewport width '0' is out of range");
    CHECK_ERROR(parse("[transform]\nviewport 0 0 10 10 0.5 0.25\n"), 2, "0 <= minz <= maxz <= 1");
    CHECK_ERROR(parse("[transform]\nviewport 0 0 10 10 0.5\n"), 2, "missing viewport maxz");
    CHECK_ERROR(parse("[constants]\nc8 0 0 0 0\n"), 2, "expected c0 ... c7");
    CHECK_ERROR(parse("[constants]\nr0 0 0 0 0\n"), 2, "unknown keyword 'r0' in [constants]");
    CHECK_ERROR(parse("[constants]\nc0 0 0 0\n"), 2, "missing c0 (4 floats)");
    CHECK_ERROR(parse("[constants]\nc0 0 0 0 1e999\n"), 2, "bad number '1e999'");
    CHECK_ERROR(parse("[constants]\nc0 0 0 0 nan\n"), 2, "bad number 'nan'");
    CHECK_ERROR(parse("[constants]\nc0 0 0 0 1e39\n"), 2, "out of range");
    CHECK_ERROR(parse("[constants]\nc1 0 0 0 0\nc1 1 1 1 1\n"), 3, "c1 set twice (first at line 2)");
    CHECK_ERROR(parse("[constants]\n[constants]\n"), 2, "duplicate section [constants]");
}

TEST_CASE("testfile: [pixel shader] blocks", "[testfile]") {
    Parsed p = parse("% header\n[pixel shader]\nps_1_1\n\n% a comment\n  tex t0   ; keep\nmov r0, t0\n[test]\n");
    REQUIRE_OK(p);
    const PixelShaderBlock& ps = p.file.pixelShader;
    CHECK(ps.present());
    CHECK(ps.line == 2);
    CHECK(ps.firstLine == 3);
    CHECK(!ps.expectFail);
    CHECK(ps.text == "ps_1_1\n\n\n  tex t0   ; keep\nmov r0, t0");
    CHECK(ps.textWithFileLines() == "\n\nps_1_1\n\n\n  tex t0   ; keep\nmov r0, t0");
    CHECK(p.file.testLine == 8);

    Parsed f = parse("[Pixel Shader Fail p2003 at 3:5]\nps_1_1\n");
    REQUIRE_OK(f);
    CHECK(f.file.pixelShader.expectFail);
    CHECK(f.file.pixelShader.failCode == "P2003");
    CHECK(f.file.pixelShader.failLine == 3);
    CHECK(f.file.pixelShader.failCol == 5);

    Parsed g = parse("[pixel shader fail P1103]\nps_1_1\n");
    REQUIRE_OK(g);
    CHECK(g.file.pixelShader.failLine == 0);
    Parsed l = parse("[pixel shader fail P1103 at 7]\nps_1_1\n");
    REQUIRE_OK(l);
    CHECK(l.file.pixelShader.failLine == 7);
    CHECK(l.file.pixelShader.failCol == 0);

    // Windows line endings and a block at the end of the file without a newline.
    Parsed w = parse("[pixel shader]\r\nps_1_1\r\nmov r0, v0");
    REQUIRE_OK(w);
    CHECK(w.file.pixelShader.text == "ps_1_1\nmov r0, v0");

    CHECK_ERROR(parse("[pixel shader fail]\nps_1_1\n"), 1, "missing diagnostic code");
    CHECK_ERROR(parse("[pixel shader fail 2003]\nps_1_1\n"), 1, "bad diagnostic code '2003'");
    CHECK_ERROR(parse("[pixel shader fail P2003 on 3:5]\n"), 1, "expected 'at LINE:COL'");
    CHECK_ERROR(parse("[pixel shader fail P2003 at x:5]\n"), 1, "bad place 'x:5'");
    CHECK_ERROR(parse("[pixel shader fail P2003 at 0:5]\n"), 1, "bad place");
    CHECK_ERROR(parse("[pixel shader fail P2003 at 3:0]\n"), 1, "bad place");
    CHECK_ERROR(parse("[pixel shader fail P2003 at]\n"), 1, "missing LINE:COL");
    CHECK_ERROR(parse("[pixel shader fail P2003 at 3:5 now]\n"), 1, "unexpected 'now'");
    CHECK_ERROR(parse("[pixel shader passes]\n"), 1, "expected 'fail CODE [at LINE:COL]'");
    CHECK_ERROR(parse("[pixel shader]\nps_1_1\n[pixel shader]\nps_1_1\n"), 3,
                "duplicate [pixel shader] section (first at line 1)");
    CHECK_ERROR(parse("[pixel shader fail P1103]\nps_1_1\n[test]\ndraw quad\n"), 3, "expected not to assemble");
}

TEST_CASE("testfile: sections and lexical errors", "[testfile]") {
    CHECK_ERROR(parse("[vertex shader]\nvs_1_1\n"), 1, "unknown section [vertex shader]");
    CHECK_ERROR(parse("[texture 0\n"), 1, "has no closing ']'");
    CHECK_ERROR(parse("[]\n"), 1, "empty section name");
    CHECK_ERROR(parse("[test] draw quad\n"), 1, "unexpected 'draw' after the section name");
    CHECK_ERROR(parse("size 2 2\n"), 1, "'size' before any section");
    CHECK_ERROR(parse("[require]\n[require]\n"), 2, "duplicate section [require]");
    CHECK_ERROR(parse("[render target]\n[render target]\n"), 2, "duplicate section [render target]");
    CHECK_ERROR(parse("[transform]\n[transform]\n"), 2, "duplicate section [transform]");
    CHECK_ERROR(parse("[test]\n[test]\n"), 2, "duplicate section [test]");
    CHECK_ERROR(parse("[render targets]\n"), 1, "unknown section [render targets]");
    // Lines under an unknown section are not reported again.
    Parsed u = parse("[bogus]\nwhatever 1 2\n");
    CHECK(u.errors.size() == 1);
    // A trailing comment on a section line is fine; anything else is not.
    REQUIRE_OK(parse("[test] % the commands\n"));
    // Numbers: hex, signs, exponents.
    Parsed n = parse("[constants]\nc0 0x10 -1 +2.5 .5\nc1 1e-3 -0.0 1E2 0XFF\n");
    REQUIRE_OK(n);
    CHECK(n.file.constants[0].value == Vec4{16, -1, 2.5f, 0.5f});
    CHECK(n.file.constants[1].value == Vec4{1e-3f, 0, 100, 255});
    CHECK_ERROR(parse("[constants]\nc0 1 2 3 4x\n"), 2, "bad number '4x'");
    CHECK_ERROR(parse("[constants]\nc0 1 2 3 0x\n"), 2, "bad number '0x'");
    CHECK_ERROR(parse("[constants]\nc0 1 2 3 -0x1\n"), 2, "bad number '-0x1'");
    CHECK_ERROR(parse("[constants]\nc0 1 2 3 inf\n"), 2, "bad number 'inf'");
    // Every error is collected, not just the first.
    Parsed many = parse("[constants]\nc0 x 0 0 0\nc1 0 y 0 0\n[bogus]\n[test]\nfly\n");
    CHECK(many.errors.size() == 4);
    CHECK(hasError(many, 2, "'x'"));
    CHECK(hasError(many, 3, "'y'"));
    CHECK(hasError(many, 4, "unknown section"));
    CHECK(hasError(many, 6, "unknown command 'fly'"));
    CHECK(formatTestFileError("a.ps11test", {6, "boom"}) == "a.ps11test:6: boom");
}

TEST_CASE("testfile: mistyped names get a suggestion", "[testfile]") {
    CHECK_ERROR(parse("[render targt]\n"), 1, "unknown section [render targt]; did you mean 'render target'?");
    CHECK_ERROR(parse("[texure 0]\n"), 1, "unknown section [texure 0]; did you mean 'texture'?");
    CHECK_ERROR(parse("[vertex shader]\n"), 1, "unknown section [vertex shader]");
    CHECK(dump(parse("[vertex shader]\n")).find("did you mean") == std::string::npos);
    CHECK_ERROR(parse("[require]\nprecison fx8\n"), 2,
                "unknown keyword 'precison' in [require] (expected version, precision, backend, max_value or hardware); "
                "did you mean 'precision'?");
    CHECK_ERROR(parse("[require]\nprecision fx9\n"), 2,
                "unknown precision 'fx9' (expected fx8, fx12, float or "
                "ideal); did you mean 'fx8'?");
    CHECK_ERROR(parse("[sampler 0]\nfiltr point\n"), 2, "did you mean 'filter'?");
    CHECK_ERROR(parse("[sampler 0]\nfilter linaer\n"), 2, "did you mean 'linear'?");
    CHECK_ERROR(parse("[stage 0]\ncolrop selectarg1\n"), 2,
                "(expected bumpenvmat, lscale, loffset, transform, texcoordindex, colorop, colorarg0-2, alphaop, "
                "alphaarg0-2 or resultarg); did you mean 'colorop'?");
    CHECK_ERROR(parse("[transform]\nveiw 1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1\n"), 2, "did you mean 'view'?");
    CHECK_ERROR(parse("[render state]\nzwirte on\n"), 2, "did you mean 'zwrite'?");
    CHECK_ERROR(parse("[test]\ndraww quad\n"), 2,
                "unknown command 'draww' in [test] (expected draw, eval or probe); "
                "did you mean 'draw'?");
    CHECK_ERROR(parse("[test]\ndraw quads\n"), 2, "did you mean 'quad'?");
}

TEST_CASE("testfile: messages quote a short excerpt of a huge token", "[testfile]") {
    const std::string huge(1 << 20, 'k');
    Parsed p = parse("[require]\n" + huge + " 1\n");
    REQUIRE(p.errors.size() == 1);
    CHECK(p.errors[0].line == 2);
    CHECK(p.errors[0].message.rfind("unknown keyword 'kkk", 0) == 0);
    CHECK(p.errors[0].message.find("…'") != std::string::npos);
    CHECK(p.errors[0].message.size() < 200);
    p = parse("[" + huge + "]\n");
    REQUIRE(p.errors.size() == 1);
    CHECK(p.errors[0].message.size() < 200);
    CHECK(formatTestFileError("a.ps11test", {0, "boom"}) == "a.ps11test: boom");
}

TEST_CASE("testfile: draw quad", "[testfile]") {
    Parsed p = parse(
        "[render target]\nsize 640 480\n"
        "[test]\n"
        "draw quad\n"
        "DRAW QUAD diffuse 0xff808080 specular 0 t0 0 0 1 1 t1 0.5 0.5 1.5 1.5\n"
        "draw quad rect 0 0 320 240 diffuse 1 0.5 0.25 1\n");
    REQUIRE_OK(p);
    const DrawQuad& a = op<DrawQuad>(p.file, 0);
    CHECK(p.file.commands[0].line == 4);
    CHECK(a.diffuse.argb == 0xffffffffu);
    CHECK(a.specular.argb == 0u);
    CHECK(a.texRect[5] == Vec4{0, 0, 1, 1});
    CHECK(!a.hasRect);
    const DrawQuad& b = op<DrawQuad>(p.file, 1);
    CHECK(b.diffuse.argb == 0xff808080u);
    CHECK(b.texRect[1] == Vec4{0.5f, 0.5f, 1.5f, 1.5f});
    const DrawQuad& c = op<DrawQuad>(p.file, 2);
    CHECK(c.hasRect);
    CHECK(c.rect == std::array<uint32_t, 4>{0, 0, 320, 240});
    CHECK(!c.diffuse.packed);
    CHECK(c.diffuse.rgba == Vec4{1, 0.5f, 0.25f, 1});

    CHECK_ERROR(parse("[test]\ndraw quad shiny\n"), 2, "unknown draw quad option 'shiny'");
    CHECK_ERROR(parse("[test]\ndraw quad t8 0 0 1 1\n"), 2, "unknown draw quad option 't8'");
    CHECK_ERROR(parse("[test]\ndraw quad t0 0 0 1\n"), 2, "missing t0 rectangle");
    CHECK_ERROR(parse("[test]\ndraw quad diffuse\n"), 2, "missing diffuse colour");
    CHECK_ERROR(parse("[test]\ndraw quad diffuse 0 diffuse 0\n"), 2, "'diffuse' given twice");
    CHECK_ERROR(parse("[test]\ndraw quad rect 4 4 2 8\n"), 2, "empty draw rect");
    CHECK_ERROR(parse("[test]\ndraw quad rect 0 0 65 8\n"), 2, "draw rect reaches outside the 64x64 render target");
    CHECK_ERROR(parse("[test]\ndraw\n"), 2, "missing primitive");
    CHECK_ERROR(parse("[test]\ndraw points xyz\n"), 2, "unknown primitive 'points'");
}

TEST_CASE("testfile: draw triangles, strip, fan", "[testfile]") {
    Parsed p = parse(
        "[test]\n"
        "draw triangles xyzrhw\n"
        "  0 0 0 1   0xffffffff 0   t0 0 0\n"
        "  64 0 0.5 0.5   0xff00ff00 0x80000000   t0 1 0  t3 1 2 3 4\n"
        "  0 64 0 1   0xffffffff 0   t7 0 1 2\n"
        "draw strip xyz\n"
        "  -1 -1 0.1  0xffffffff 0  t0 0 1 0 1\n"
        "  -1 1 0.1  0xffffffff 0\n"
        "  1 -1 0.1  0xffffffff 0\n"
        "draw fan xyz\n"
        "  -1 -1 0  0 0\n  1 -1 0  0 0\n  1 1 0  0 0\n  -1 1 0  0 0\n");
    REQUIRE_OK(p);
    const DrawPrimitives& t = op<DrawPrimitives>(p.file, 0);
    CHECK(t.type == PrimitiveType::TriangleList);
    CHECK(t.pretransformed);
    REQUIRE(t.vertices.size() == 3);
    CHECK(t.vertices[0].line == 3);
    CHECK(t.vertices[1].position == Vec4{64, 0, 0.5f, 0.5f});
    CHECK(t.vertices[1].diffuse == 0xff00ff00u);
    CHECK(t.vertices[1].specular == 0x80000000u);
    CHECK(t.vertices[1].texComponents[0] == 2);
    CHECK(t.vertices[1].tex[0] == Vec4{1, 0, 0, 0});
    CHECK(t.vertices[1].texComponents[3] == 4);
    CHECK(t.vertices[1].tex[3] == Vec4{1, 2, 3, 4});
    CHECK(t.vertices[2].texComponents[7] == 3);
    CHECK(t.vertices[2].texComponents[0] == 0);
    const DrawPrimitives& s = op<DrawPrimitives>(p.file, 1);
    CHECK(s.type == PrimitiveType::TriangleStrip);
    CHECK(!s.pretransformed);
    CHECK(s.vertices[0].position == Vec4{-1, -1, 0.1f, 1});
    CHECK(s.vertices[0].texComponents[0] == 4);
    const DrawPrimitives& f = op<DrawPrimitives>(p.file, 2);
    CHECK(f.type == PrimitiveType::TriangleFan);
    CHECK(f.vertices.size() == 4);

    CHECK_ERROR(parse("[test]\ndraw triangles\n"), 2, "missing vertex format");
    CHECK_ERROR(parse("[test]\ndraw triangles xyzw\n"), 2, "unknown vertex format 'xyzw'");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 0 0 0\n0 0 0 0 0\n"), 2,
                "draw triangles has 2 vertices (a positive multiple of 3 needed)");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n"), 2, "draw triangles has 0 vertices");
    CHECK_ERROR(parse("[test]\ndraw strip xyz\n0 0 0 0 0\n[test]\n"), 2, "draw strip has 1 vertices");
    CHECK_ERROR(parse("[test]\ndraw fan xyz\n0 0 0 0 0\n0 0 0 0 0\nprobe all rgba 0\n"), 2, "draw fan has 2");
    CHECK_ERROR(parse("[test]\n0 0 0 0 0\n"), 2, "vertex line without a 'draw triangles|strip|fan'");
    CHECK_ERROR(parse("[test]\ndraw quad\n0 0 0 0 0\n"), 3, "vertex line without");
    CHECK_ERROR(parse("[test]\ndraw triangles xyzrhw\n0 0 0 0 0 0\n0 0 0 1 0 0\n0 0 0 1 0 0\n"), 3, "rhw must be > 0");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 0\n"), 3, "missing vertex diffuse colour");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 0 0xff\n"), 3, "missing vertex specular colour");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 0 1.5 0\n"), 3, "bad vertex diffuse colour '1.5'");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 0 0 0 t0 1\n"), 3, "'t0' needs 2 to 4 coordinates");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 0 0 0 t0 1 2 3 4 5\n"), 3, "unexpected '5' in a vertex");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 0 0 0 t0 1 2 t0 1 2\n"), 3, "'t0' given twice");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 0 0 0 t8 1 2\n"), 3, "unexpected 't8'");
    CHECK_ERROR(parse("[test]\ndraw triangles xyz\n0 0 x 0 0\n"), 3, "bad number 'x' for vertex z");
    // A draw line in error swallows its vertex lines instead of reporting each of them.
    Parsed bad = parse("[test]\ndraw triangles uvw\n0 0 0 0 0\n0 0 0 0 0\n0 0 0 0 0\n");
    CHECK(bad.errors.size() == 1);
}

TEST_CASE("testfile: eval and probes", "[testfile]") {
    Parsed p = parse(
        "[pixel shader]\nps_1_1\nmov r0, v0\n"
        "[test]\n"
        "eval\n"
        "  v0 0.5 0.5 0.5 1\n"
        "  v1 0xff0000ff\n"
        "  t0 0.25 0.75 0 1\n"
        "  T3 1\n"
        "probe 10 10 rgba 0xff808080 tol 1\n"
        "probe 10 10 rgb 0x808080 tol 1\n"
        "probe rect 0 0 32 32 rgba 0xff808080 tol 1\n"
        "probe all rgba 0xff808080 tol 0\n"
        "probe eval rgba 0.5 0.5 0.5 1.0 tol 0.004\n"
        "probe eval rgb 0.5 0.5 0.5 tol 0.004\n"
        "probe eval killed\n"
        "probe 10 10 rgba 0.25 0.5 0.75 1 tol 1e-6\n"
        "probe 63 63 rgba 0\n");
    REQUIRE_OK(p);
    const Eval& e = op<Eval>(p.file, 0);
    CHECK(e.color[0].value == Vec4{0.5f, 0.5f, 0.5f, 1});
    CHECK(e.color[0].line == 6);
    CHECK(e.color[1].value == Vec4{0, 0, 1, 1});
    CHECK(e.texture[0].value == Vec4{0.25f, 0.75f, 0, 1});
    CHECK(e.texture[3].value == Vec4{1, 0, 0, 0});
    CHECK(!e.texture[1].isSet());
    const Probe& a = op<Probe>(p.file, 1);
    CHECK(a.kind == ProbeKind::Pixel);
    CHECK(a.rect == std::array<uint32_t, 4>{10, 10, 11, 11});
    CHECK(a.alpha);
    CHECK(a.expected.argb == 0xff808080u);
    CHECK(a.tolerance == 1.0f);
    const Probe& b = op<Probe>(p.file, 2);
    CHECK(!b.alpha);
    CHECK(b.expected.argb == 0x808080u);
    const Probe& c = op<Probe>(p.file, 3);
    CHECK(c.kind == ProbeKind::Rect);
    CHECK(c.rect == std::array<uint32_t, 4>{0, 0, 32, 32});
    CHECK(op<Probe>(p.file, 4).kind == ProbeKind::All);
    const Probe& ev = op<Probe>(p.file, 5);
    CHECK(ev.kind == ProbeKind::Eval);
    CHECK(!ev.expected.packed);
    CHECK(ev.expected.rgba == Vec4{0.5f, 0.5f, 0.5f, 1});
    CHECK(ev.tolerance == 0.004f);
    const Probe& evRgb = op<Probe>(p.file, 6);
    CHECK(!evRgb.alpha);
    CHECK(evRgb.expected.rgba[2] == 0.5f);
    CHECK(op<Probe>(p.file, 7).kind == ProbeKind::EvalKilled);
    CHECK(op<Probe>(p.file, 8).expected.rgba == Vec4{0.25f, 0.5f, 0.75f, 1});
    CHECK(op<Probe>(p.file, 9).tolerance == 0.0f);

    const char* shader = "[pixel shader]\nps_1_1\nmov r0, v0\n[test]\n";
    auto withShader = [&](const std::string& s) { return parse(shader + s); };
    CHECK_ERROR(withShader("eval extra\n"), 5, "unexpected 'extra'");
    CHECK_ERROR(withShader("eval\nv2 1 1 1 1\n"), 6, "no interpolant 'v2' (v0 or v1)");
    CHECK_ERROR(withShader("eval\nt8 1 1 1 1\n"), 6, "no interpolant 't8'");
    CHECK_ERROR(withShader("eval\nv0 1 1 1 1\nv0 0\n"), 7, "'v0' given twice (first at line 6)");
    CHECK_ERROR(withShader("eval\nv0 1 1 1 1 1\n"), 6, "unexpected '1'");
    CHECK_ERROR(withShader("eval\nv0\n"), 6, "missing v0 value");
    CHECK_ERROR(withShader("v0 1 1 1 1\n"), 5, "interpolant 'v0' outside an eval");
    CHECK_ERROR(withShader("draw quad\nt0 1 1\n"), 6, "interpolant 't0' outside an eval");
    CHECK_ERROR(parse("[test]\neval\n"), 2, "eval needs a [pixel shader]");
    CHECK_ERROR(withShader("probe eval rgba 0 tol 0\n"), 5, "probe eval without an eval before it");
    CHECK_ERROR(withShader("probe eval killed\neval\n"), 5, "probe eval without an eval");
    CHECK_ERROR(withShader("probe\n"), 5, "missing probe target");
    CHECK_ERROR(withShader("probe somewhere rgba 0\n"), 5, "unknown probe target 'somewhere'");
    CHECK_ERROR(withShader("probe 1 1\n"), 5, "missing channels");
    CHECK_ERROR(withShader("probe 1 1 rg 0\n"), 5, "unknown probe channels 'rg'");
    CHECK_ERROR(withShader("probe 1 1 rgba\n"), 5, "missing expected colour");
    CHECK_ERROR(withShader("probe 1 1 rgba 0.5 0.5 0.5 tol 1\n"), 5, "one 0xAARRGGBB word or 4 floats");
    CHECK_ERROR(withShader("probe 1 1 rgb 0.5 0.5 tol 1\n"), 5, "one 0xAARRGGBB word or 3 floats");
    CHECK_ERROR(withShader("probe 1 1 rgba 0 tol\n"), 5, "missing tolerance");
    CHECK_ERROR(withShader("probe 1 1 rgba 0 tol -1\n"), 5, "tolerance must be >= 0");
    CHECK_ERROR(withShader("probe 1 1 rgba 0 tol 1 more\n"), 5, "unexpected 'more'");
    CHECK_ERROR(withShader("probe 64 0 rgba 0\n"), 5, "probe reaches outside the 64x64 render target");
    CHECK_ERROR(withShader("probe rect 0 0 65 1 rgba 0\n"), 5, "probe reaches outside");
    CHECK_ERROR(withShader("probe rect 4 0 4 1 rgba 0\n"), 5, "empty probe rect");
    CHECK_ERROR(withShader("probe 1.5 0 rgba 0\n"), 5, "probe x must be an integer");
    CHECK_ERROR(withShader("probe -1 0 rgba 0\n"), 5, "probe x '-1' is out of range");
    CHECK_ERROR(withShader("explode\n"), 5, "unknown command 'explode' in [test]");

    Parsed depth = withShader("eval\nt0 1\nprobe eval depth 0.25 tol 1e-6\nprobe eval depth 1\n");
    REQUIRE_OK(depth);
    const Probe& d0 = op<Probe>(depth.file, 1);
    CHECK(d0.kind == ProbeKind::EvalDepth);
    CHECK(d0.depth == 0.25f);
    CHECK(d0.tolerance == 1e-6f);
    CHECK(op<Probe>(depth.file, 2).tolerance == 0.0f);
    CHECK(isEvalProbe(ProbeKind::EvalDepth));
    CHECK(!isEvalProbe(ProbeKind::All));
    CHECK_ERROR(withShader("probe eval depth 0.5\n"), 5, "probe eval without an eval before it");
    CHECK_ERROR(withShader("eval\nprobe eval depth\n"), 6, "missing expected depth");
    CHECK_ERROR(withShader("eval\nprobe eval depth 0.5 tol\n"), 6, "missing tolerance");
    CHECK_ERROR(withShader("eval\nprobe eval depth 0.5 0.5\n"), 6, "unexpected '0.5'");
}

TEST_CASE("testfile: if() and todo() prefixes", "[testfile]") {
    Parsed p = parse(
        "[test]\n"
        "if(gl) probe 0 0 rgba 0\n"
        "if(fx8) probe 0 0 rgba 0\n"
        "todo(gl) probe 0 0 rgba 0\n"
        "if (emu, fx12) todo ( ideal ) probe 0 0 rgba 0\n"
        "todo probe 0 0 rgba 0\n"
        "IF(GL) draw quad\n");
    REQUIRE_OK(p);
    const auto& c = p.file.commands;
    const HardwareClass& gf4 = *findHardware("geforce4");
    REQUIRE(c.size() == 6);
    CHECK(c[0].onlyIf.backends == kBackendGl);
    CHECK(c[0].onlyIf.matches(Backend::Gl, Precision::Fx8, gf4));
    CHECK(!c[0].onlyIf.matches(Backend::Emu, Precision::Fx8, gf4));
    CHECK(c[1].onlyIf.precisions == kPrecisionFx8);
    CHECK(c[1].onlyIf.matches(Backend::Gl, Precision::Fx8, gf4));
    CHECK(!c[1].onlyIf.matches(Backend::Gl, Precision::Ideal, gf4));
    CHECK(c[2].todo);
    CHECK(c[2].isTodo(Backend::Gl, Precision::Fx8, gf4));
    CHECK(!c[2].isTodo(Backend::Emu, Precision::Fx8, gf4));
    CHECK(c[2].onlyIf.matches(Backend::Emu, Precision::Fx8, gf4));
    CHECK(c[3].onlyIf.backends == kBackendEmu);
    CHECK(c[3].onlyIf.precisions == kPrecisionFx12);
    CHECK(c[3].isTodo(Backend::Emu, Precision::Ideal, gf4));
    CHECK(!c[3].isTodo(Backend::Emu, Precision::Fx12, gf4));
    CHECK(c[4].isTodo(Backend::Emu, Precision::Fx8, gf4));
    CHECK(c[4].isTodo(Backend::Gl, Precision::Ideal, gf4));
    CHECK(c[5].onlyIf.backends == kBackendGl);
    CHECK(std::holds_alternative<DrawQuad>(c[5].op));

    CHECK_ERROR(parse("[test]\nif(d3d) probe 0 0 rgba 0\n"), 2, "unknown condition 'd3d'");

    // Hardware classes as conditions: if(radeon8500) runs only on that class.
    Parsed h = parse("[test]\nif(radeon8500, D3D9) probe 0 0 rgba 0\ntodo(geforce3) probe 0 0 rgba 0\n");
    REQUIRE_OK(h);
    const HardwareClass& r200 = *findHardware("radeon8500");
    const HardwareClass& d3d9 = *findHardware("d3d9");
    CHECK(h.file.commands[0].onlyIf.matches(Backend::Emu, Precision::Fx8, r200));
    CHECK(h.file.commands[0].onlyIf.matches(Backend::Emu, Precision::Fx8, d3d9));
    CHECK(!h.file.commands[0].onlyIf.matches(Backend::Emu, Precision::Fx8, gf4));
    CHECK(h.file.commands[1].isTodo(Backend::Emu, Precision::Fx8, *findHardware("geforce3")));
    CHECK(!h.file.commands[1].isTodo(Backend::Emu, Precision::Fx8, gf4));
    CHECK_ERROR(parse("[test]\nif() probe 0 0 rgba 0\n"), 2, "empty condition '()'");
    CHECK_ERROR(parse("[test]\nif(gl probe 0 0 rgba 0\n"), 2, "unknown condition 'probe'");
    CHECK_ERROR(parse("[test]\nif(gl\n"), 2, "missing ')' after the condition");
    CHECK_ERROR(parse("[test]\nif gl probe 0 0 rgba 0\n"), 2, "missing '(' after the prefix");
    CHECK_ERROR(parse("[test]\nif(gl) if(fx8) probe 0 0 rgba 0\n"), 2, "more than one if(...) prefix");
    CHECK_ERROR(parse("[test]\ntodo todo probe 0 0 rgba 0\n"), 2, "more than one todo prefix");
    CHECK_ERROR(parse("[test]\ntodo(gl) draw quad\n"), 2, "todo applies to probes only");
    CHECK_ERROR(parse("[test]\nif(gl)\n"), 2, "missing command after the prefix");
}

TEST_CASE("testfile: the format corpus parses", "[testfile]") {
    namespace fs = std::filesystem;
    fs::path dir = fs::path(PS11_SOURCE_DIR) / "tests" / "shaders" / "format";
    REQUIRE(fs::is_directory(dir));
    int count = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
        if (e.path().extension() != ".ps11test") continue;
        std::ifstream in(e.path(), std::ios::binary);
        std::stringstream ss;
        ss << in.rdbuf();
        Parsed p = parse(ss.str());
        INFO(e.path().string());
        REQUIRE_OK(p);
        ++count;
    }
    CHECK(count >= 5);
}

TEST_CASE("testfile: the examples in docs/test-format.md parse", "[testfile][docs]") {
    std::ifstream in(std::filesystem::path(PS11_SOURCE_DIR) / "docs" / "test-format.md", std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string page = ss.str();
    REQUIRE(!page.empty());
    int blocks = 0;
    for (size_t pos = page.find("```ps11test\n"); pos != std::string::npos; pos = page.find("```ps11test\n", pos)) {
        pos += 12;
        size_t end = page.find("```", pos);
        REQUIRE(end != std::string::npos);
        Parsed p = parse(page.substr(pos, end - pos));
        INFO(page.substr(pos, end - pos));
        REQUIRE_OK(p);
        pos = end + 3;
        ++blocks;
    }
    CHECK(blocks >= 3);
}
