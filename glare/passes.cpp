#include "glare/passes.h"

#include <cmath>

#include "glare/runner.h"

namespace glare {

Tap texelTap(const FrameBuild& fb, TextureId texture, float dx, float dy, D3DTEXTUREFILTERTYPE filter) {
    const TextureDesc& d = fb.graph.texture(texture).desc;
    return Tap{texture, emu::shifted(dx / float(d.width), dy / float(d.height)), filter};
}

Tap pointTap(TextureId texture, float u, float v, D3DTEXTUREFILTERTYPE filter) {
    return Tap{texture, emu::QuadCoords{u, v, u, v}, filter};
}

namespace {
std::vector<double> diffuse(const std::vector<double>& weights, double steps) {
    std::vector<double> out;
    double exact = 0, given = 0;
    for (double w : weights) {
        exact += w;
        const double q = std::nearbyint(exact * steps) / steps - given;  // keeps Σq = Q(Σw)
        out.push_back(q);
        given += q;
    }
    return out;
}
}  // namespace

std::vector<double> quantiseWeights(const std::vector<double>& weights, ps11::Precision precision) {
    if (precision == ps11::Precision::Fx8) return diffuse(weights, 255);
    if (precision == ps11::Precision::Fx12) return diffuse(weights, 4080);
    return weights;
}

std::vector<double> quantiseWeights8(const std::vector<double>& weights) { return diffuse(weights, 255); }

bool setBlend(PassContext& c, Blend blend) {
    emu::Device& d = c.device;
    if (!c.check(d.SetRenderState(D3DRS_ALPHABLENDENABLE, blend != Blend::None))) return false;
    if (blend == Blend::Add)
        return c.check(d.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_ONE)) &&
               c.check(d.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_ONE)) &&
               c.check(d.SetRenderState(D3DRS_BLENDOP, D3DBLENDOP_ADD));
    if (blend == Blend::Alpha)
        return c.check(d.SetRenderState(D3DRS_SRCBLEND, D3DBLEND_SRCALPHA)) &&
               c.check(d.SetRenderState(D3DRS_DESTBLEND, D3DBLEND_INVSRCALPHA)) &&
               c.check(d.SetRenderState(D3DRS_BLENDOP, D3DBLENDOP_ADD));
    return true;
}

bool bindTap(PassContext& c, DWORD stage, const Tap& tap) {
    emu::Device& d = c.device;
    return c.check(d.SetTexture(stage, c.texture(tap.texture))) &&
           c.check(d.SetSamplerState(stage, D3DSAMP_ADDRESSU, D3DTADDRESS_CLAMP)) &&
           c.check(d.SetSamplerState(stage, D3DSAMP_ADDRESSV, D3DTADDRESS_CLAMP)) &&
           c.check(d.SetSamplerState(stage, D3DSAMP_MINFILTER, tap.filter)) &&
           c.check(d.SetSamplerState(stage, D3DSAMP_MAGFILTER, tap.filter)) &&
           c.check(d.SetSamplerState(stage, D3DSAMP_MIPFILTER, D3DTEXF_NONE));
}

bool drawQuadPass(PassContext& c, Runner& runner, const QuadPass& q) {
    emu::Device& d = c.device;
    std::string err;
    const emu::Handle ps = runner.shader(q.shader, err);
    if (ps == emu::Handle::Null) {
        c.error = "pass " + c.stats.pass + ": " + err;
        return false;
    }
    if (!c.setTarget(q.target) || !setBlend(c, q.blend) || !c.check(d.SetPixelShader(ps))) return false;
    std::array<emu::QuadCoords, 4> coords{};
    for (DWORD s = 0; s < 4; ++s) {
        if (s >= q.taps.size()) {
            if (!c.check(d.SetTexture(s, emu::Handle::Null))) return false;
            continue;
        }
        coords[s] = q.taps[s].coords;
        if (!bindTap(c, s, q.taps[s])) return false;
    }
    for (const auto& [reg, value] : q.constants)
        if (!c.check(d.SetPixelShaderConstantF(UINT(reg), value.data(), 1))) return false;
    return c.drawQuad(coords);
}

void addQuadPass(FrameBuild& fb, const std::string& name, const std::string& note, const QuadPass& q) {
    Runner* runner = &fb.runner;
    PassInfo info{name, PassKind::Shader, q.shader, note, q.constants};
    for (size_t i = 0; i < q.taps.size(); ++i) {
        if (q.taps[i].filter == D3DTEXF_POINT) info.pointStages = uint8_t(info.pointStages | (1u << i));
        info.stages.push_back(PassStage{q.taps[i].texture, q.taps[i].coords, q.taps[i].filter});
    }
    info.blend = q.blend;
    fb.graph.addPass(
        std::move(info),
        [&](PassBuilder& b) {
            for (const Tap& t : q.taps) b.read(t.texture);
            if (q.blend != Blend::None) b.read(q.target);
            b.write(q.target);
        },
        [runner, q](PassContext& c) { return drawQuadPass(c, *runner, q); });
}

void addStretchPass(FrameBuild& fb, const std::string& name, TextureId source, TextureId dest,
                    D3DTEXTUREFILTERTYPE filter) {
    const std::string note = std::string(filter == D3DTEXF_LINEAR ? "bilinear" : "point") + " copy";
    PassInfo info{name, PassKind::StretchRect, "", note};
    info.stages.push_back(PassStage{source, {}, filter});
    fb.graph.addPass(
        info,
        [&](PassBuilder& b) {
            b.read(source);
            b.write(dest);
        },
        [=](PassContext& c) { return c.stretch(source, dest, filter); });
}

void addClearPass(FrameBuild& fb, const std::string& name, TextureId target, D3DCOLOR colour) {
    fb.graph.addPass(
        PassInfo{name, PassKind::Clear, "", "clear"}, [&](PassBuilder& b) { b.write(target); },
        [=](PassContext& c) { return c.clear(target, colour); });
}

}  // namespace glare
