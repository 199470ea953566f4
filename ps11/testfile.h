// The .ps11test reader: one self-contained shader test (resources, state, a pixel shader or a
// fixed-function stage setup, draws, evals and probes) parsed into plain data that the device
// and the executor can replay. The format is described in docs/test-format.md. Errors are
// collected (never thrown) as `FILE:LINE: message`; the model is filled as far as possible.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "ps11/caps.h"
#include "ps11/formats.h"
#include "ps11/hardware.h"
#include "ps11/precision.h"

namespace ps11 {

using Vec4 = std::array<float, 4>;
using Matrix4 = std::array<float, 16>;  // row-major, D3D row-vector convention

// A value the file may set. `value` holds D3D9's default until the file sets it; `line` is the
// line that set it (0 = not set).
template <class T>
struct Setting {
    T value{};
    uint32_t line = 0;
    bool isSet() const { return line != 0; }
};

enum class Backend : uint8_t { Emu, Gl };

// Bit masks over Backend / Precision (bit = 1 << enum value).
enum : uint8_t { kBackendEmu = 1, kBackendGl = 2, kAllBackends = 3 };
enum : uint8_t { kPrecisionFx8 = 1, kPrecisionFx12 = 2, kPrecisionFloat = 4, kPrecisionIdeal = 8 };

const char* backendName(Backend b);

// A colour as written: one word 0xAARRGGBB (`packed`), or four floats r g b a. `rgba` always
// holds the value (a packed word converted channel / 255).
struct Color {
    Vec4 rgba{0, 0, 0, 0};
    bool packed = true;
    uint32_t argb = 0;
    static Color fromArgb(uint32_t argb);
    static Color fromFloats(const Vec4& rgba);
};

// One texel as written: a word in the format's natural packing (count == 0), or 1-4 floats in
// parentheses (count = how many; the rest of `value` is 0, 0, 0, 1).
struct Texel {
    uint32_t bits = 0;
    Vec4 value{0, 0, 0, 1};
    uint8_t count = 0;
};

struct TextureLevel {
    uint32_t line = 0;  // the `level` line
    uint32_t level = 0;
    uint32_t width = 0, height = 0, depth = 1;  // this level's extent
    bool hasFill = false;
    Texel fill;                 // the whole level is this texel (hasFill)
    std::vector<Texel> texels;  // otherwise width*height*depth: rows top first, slice after slice
};

struct TextureDesc {
    uint32_t line = 0;  // the [texture N] line
    int stage = 0;
    Setting<TexFormat> format{TexFormat::A8R8G8B8};
    uint32_t width = 0, height = 0, depth = 0;  // depth 0 = a 2D texture, > 0 = a volume texture
    uint32_t sizeLine = 0;
    Setting<uint32_t> levels{1};     // 0 = build the full chain from level 0
    std::vector<TextureLevel> data;  // sorted by level
    bool isVolume() const { return depth > 0; }
};


struct SamplerDesc {
    uint32_t line = 0;
    int stage = 0;
    Setting<Filter> minFilter{Filter::Point}, magFilter{Filter::Point}, mipFilter{Filter::None};
    Setting<TextureAddress> addressU{TextureAddress::Wrap}, addressV{TextureAddress::Wrap}, addressW{TextureAddress::Wrap};
    Setting<Color> border;
};

// D3DTOP_* (values as in d3d9types.h).
// D3DTOP_* (values as in d3d9types.h); a file may also write any other DWORD (a number), which
// SetTextureStageState takes.
enum class TextureOp : uint32_t {
    Disable = 1,
    SelectArg1,
    SelectArg2,
    Modulate,
    Modulate2x,
    Modulate4x,
    Add,
    AddSigned,
    AddSigned2x,
    Subtract,
    AddSmooth,
    BlendDiffuseAlpha,
    BlendTextureAlpha,
    BlendFactorAlpha,
    BlendTextureAlphaPm,
    BlendCurrentAlpha,
    PreModulate,
    ModulateAlphaAddColor,
    ModulateColorAddAlpha,
    ModulateInvAlphaAddColor,
    ModulateInvColorAddAlpha,
    BumpEnvMap,
    BumpEnvMapLuminance,
    DotProduct3,
    MultiplyAdd,
    Lerp,
};
const char* textureOpName(TextureOp op);  // lower case, as written in the file

// D3DTA_* argument sources (values as in d3d9types.h).
enum class ArgSource : uint8_t { Diffuse = 0, Current = 1, Texture = 2, TFactor = 3, Specular = 4, Temp = 5 };

struct TextureArg {
    ArgSource source = ArgSource::Current;  // D3DTA_SELECTMASK bits (a number may give any 0-15)
    bool complement = false;      // D3DTA_COMPLEMENT: 1 - x
    bool alphaReplicate = false;  // D3DTA_ALPHAREPLICATE: x.aaaa
    uint32_t otherBits = 0;       // bits above D3DTA_ALPHAREPLICATE a number may set
    bool operator==(const TextureArg&) const = default;
};

// D3DTSS_TEXTURETRANSFORMFLAGS as written: D3DTTFF_COUNTn (the low byte) | D3DTTFF_PROJECTED
// (256), or any other DWORD (SetTextureStageState takes every value).
struct TransformFlags {
    uint32_t bits = 0;
    bool operator==(const TransformFlags&) const = default;
};

// Texture stage state; values start at D3D9's defaults for this stage.
struct StageDesc {
    uint32_t line = 0;
    int stage = 0;
    Setting<Vec4> bumpEnvMat;  // MAT00 MAT01 MAT10 MAT11
    Setting<float> lScale, lOffset;
    Setting<TransformFlags> transformFlags;
    Setting<uint32_t> texCoordIndex;
    Setting<TextureOp> colorOp, alphaOp;
    Setting<TextureArg> colorArg0, colorArg1, colorArg2, alphaArg0, alphaArg1, alphaArg2, resultArg;
};
StageDesc defaultStage(int stage);

// D3DBLEND_* / D3DBLENDOP_* / D3DCMP_* / D3DCULL_* (values as in d3d9types.h).
enum class Blend : uint8_t {
    Zero = 1,
    One,
    SrcColor,
    InvSrcColor,
    SrcAlpha,
    InvSrcAlpha,
    DestAlpha,
    InvDestAlpha,
    DestColor,
    InvDestColor,
    SrcAlphaSat,
    BothSrcAlpha,
    BothInvSrcAlpha,
    BlendFactor,
    InvBlendFactor,
};
enum class BlendOp : uint8_t { Add = 1, Subtract, RevSubtract, Min, Max };
enum class CompareFunc : uint8_t { Never = 1, Less, Equal, LessEqual, Greater, NotEqual, GreaterEqual, Always };
enum class CullMode : uint8_t { None = 1, Cw, Ccw };

enum : uint8_t { kWriteR = 1, kWriteG = 2, kWriteB = 4, kWriteA = 8 };  // D3DCOLORWRITEENABLE_*

struct RenderStateDesc {
    uint32_t line = 0;
    Setting<bool> alphaBlend{false};
    Setting<Blend> srcBlend{Blend::One}, destBlend{Blend::Zero};
    Setting<BlendOp> blendOp{BlendOp::Add};
    Setting<Color> blendFactor{Color::fromArgb(0xffffffff)};
    Setting<bool> alphaTest{false};
    Setting<CompareFunc> alphaFunc{CompareFunc::Always};
    Setting<uint32_t> alphaRef{0};
    Setting<Color> textureFactor{Color::fromArgb(0xffffffff)};
    Setting<bool> fog{false};
    Setting<Color> fogColor;
    Setting<CompareFunc> zFunc{CompareFunc::LessEqual};
    Setting<bool> zWrite{true};
    Setting<uint8_t> colorWrite{15};
    // Unlike D3D9 (CCW) tests default to no culling, so vertex order never hides a triangle.
    Setting<CullMode> cullMode{CullMode::None};
};

struct RenderTargetDesc {
    uint32_t line = 0;
    Setting<std::array<uint32_t, 2>> size{{64, 64}};
    Setting<TexFormat> format{TexFormat::A8R8G8B8};
    Setting<Color> clear;
    Setting<bool> depth{false};
    float depthClear = 1.0f;
};

struct Viewport {
    uint32_t x = 0, y = 0, width = 0, height = 0;  // width 0 = the whole target
    float minZ = 0, maxZ = 1;
};

struct TransformDesc {
    uint32_t line = 0;
    Setting<Matrix4> world, view, projection;  // identity unless set
    std::array<Setting<Matrix4>, kMaxTextureStages> texture;  // D3DTS_TEXTURE0..7
    Setting<Viewport> viewport;
};
Matrix4 identityMatrix();

struct ConstantDesc {
    uint32_t line = 0;
    int index = 0;
    Vec4 value{};
};

struct RequireDesc {
    uint32_t line = 0;
    Setting<int> versionMinor{1};  // ps_1_<versionMinor>
    Setting<Precision> precision{Precision::Fx8};
    Setting<uint8_t> backends{kAllBackends};
    Setting<float> maxValue{0};  // 0 = the hardware class's PixelShader1xMaxValue
    Setting<const HardwareClass*> hardware{nullptr};  // null = the default class of the shader's version
};

struct PixelShaderBlock {
    uint32_t line = 0;       // the [pixel shader] line; 0 = none (the fixed-function stages draw)
    uint32_t firstLine = 0;  // file line of the block's first text line
    std::string text;        // the block's lines joined with '\n' ('%' comment lines left empty)
    bool expectFail = false;
    std::string failCode;                // e.g. "P2003"
    uint32_t failLine = 0, failCol = 0;  // `at LINE:COL` (file lines); 0 = anywhere
    bool present() const { return line != 0; }
    // The text preceded by firstLine - 1 empty lines, so diagnostics carry file lines.
    std::string textWithFileLines() const;
};

// `if(...)` / `todo(...)` conditions: a mask of backends, of precisions and of hardware classes
// (bit = hardwareIndex; 0 = any).
struct Condition {
    uint8_t backends = 0;
    uint8_t precisions = 0;
    uint32_t hardware = 0;
    bool matches(Backend b, Precision p, const HardwareClass& hw) const;
};

struct DrawQuad {
    Color diffuse = Color::fromArgb(0xffffffff);
    Color specular = Color::fromArgb(0);
    std::array<Vec4, kMaxTexCoordSets> texRect;  // u0 v0 u1 v1 per coordinate set, (0,0)-(1,1) by default
    bool hasRect = false;
    std::array<uint32_t, 4> rect{};  // x0 y0 x1 y1 in pixels (x1, y1 exclusive)
    DrawQuad();
};

struct Vertex {
    uint32_t line = 0;
    Vec4 position{0, 0, 0, 1};  // x y z rhw (rhw = 1 for untransformed vertices)
    uint32_t diffuse = 0xffffffff;
    uint32_t specular = 0;
    std::array<Vec4, 8> tex{};               // given components; the rest 0
    std::array<uint8_t, 8> texComponents{};  // 0 = set not given, else 2-4
};

enum class PrimitiveType : uint8_t { TriangleList, TriangleStrip, TriangleFan };

struct DrawPrimitives {
    PrimitiveType type = PrimitiveType::TriangleList;
    bool pretransformed = false;  // xyzrhw
    std::vector<Vertex> vertices;
};

struct Eval {
    std::array<Setting<Vec4>, 2> color;    // v0, v1 (missing ones are 0)
    std::array<Setting<Vec4>, kMaxTexCoordSets> texture;  // t0 ... (missing ones are 0)
};

enum class ProbeKind : uint8_t { Pixel, Rect, All, Eval, EvalKilled, EvalDepth };
// True for the probes that look at the last eval (not at the render target).
constexpr bool isEvalProbe(ProbeKind k) { return k == ProbeKind::Eval || k == ProbeKind::EvalKilled || k == ProbeKind::EvalDepth; }

struct Probe {
    ProbeKind kind = ProbeKind::Pixel;
    std::array<uint32_t, 4> rect{};  // x0 y0 x1 y1 (exclusive); a pixel probe is 1x1
    bool alpha = true;               // rgba (true) or rgb
    Color expected;
    float tolerance = 0;  // 8-bit levels on 8-bit targets, absolute otherwise
    float depth = 0;      // EvalDepth: the expected depth the shader wrote
};

struct TestCommand {
    uint32_t line = 0;
    Condition onlyIf;   // run only where this matches
    bool todo = false;  // a known failure where todoIf matches (probes only)
    Condition todoIf;
    std::variant<DrawQuad, DrawPrimitives, Eval, Probe> op;
    bool isTodo(Backend b, Precision p, const HardwareClass& hw) const { return todo && todoIf.matches(b, p, hw); }
};

struct TestFile {
    std::string fileName;
    RequireDesc require;
    RenderTargetDesc renderTarget;
    std::vector<TextureDesc> textures;  // in file order, one per stage
    std::vector<SamplerDesc> samplers;
    std::vector<StageDesc> stages;
    RenderStateDesc renderState;
    TransformDesc transform;
    std::vector<ConstantDesc> constants;
    PixelShaderBlock pixelShader;
    uint32_t testLine = 0;  // the [test] line (0 = no [test] section)
    std::vector<TestCommand> commands;

    const TextureDesc* texture(int stage) const;
    const SamplerDesc* sampler(int stage) const;
    const StageDesc* stage(int stage) const;
};

struct TestFileError {
    uint32_t line = 0;  // 0 = the whole file
    std::string message;
};

// Parses a whole .ps11test. Returns true if there were no errors; every error is appended to
// `errors` and parsing goes on, so `out` is as complete as the input allows.
bool parseTestFile(std::string_view text, const std::string& fileName, TestFile& out,
                   std::vector<TestFileError>& errors);

// "FILE:LINE: message" (or "FILE: message" for line 0).
std::string formatTestFileError(const std::string& fileName, const TestFileError& error);

// Limits that keep hostile input from asking for absurd allocations.
// (Sides: kMaxTextureSide and kMaxVolumeSide of ps11/caps.h.)
constexpr uint64_t kMaxTexels = uint64_t(kMaxTextureSide) * kMaxTextureSide;

}  // namespace ps11
