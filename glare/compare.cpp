#include "glare/compare.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "emu/format.h"

namespace glare {

namespace {

// Channel values of a read-back texel in 8-bit levels (float formats scaled by 255).
void levelsOf(const emu::SurfacePixels& px, size_t i, double out[4]) {
    const emu::FormatInfo& info = *emu::formatInfo(px.format);
    const uint8_t* p = &px.bytes[i * px.bytesPerPixel];
    if (info.cls == emu::FormatClass::Unorm8) {
        const auto b = emu::decodeUnorm8(info, p);
        for (int c = 0; c < 4; ++c) out[c] = b[size_t(c)];
    } else {
        const auto v = emu::decodeTexel(info, p, ps11::SignedDecode{});
        for (int c = 0; c < 4; ++c) out[c] = double(v[size_t(c)]) * 255.0;
    }
}

std::optional<emu::SurfacePixels> capture(Runner& r, const PassGraph& g, TextureId id, std::string& e) {
    emu::Handle s{};
    if (r.device().GetSurfaceLevel(g.texture(id).device, 0, &s) != D3D_OK) {
        e = r.device().lastError().message;
        return std::nullopt;
    }
    return emu::readSurface(r.device(), s, e);
}

}  // namespace

void accumulate(PassAgreement& a, const emu::SurfacePixels& x, const emu::SurfacePixels& y) {
    const size_t n = size_t(x.width) * x.height;
    for (size_t i = 0; i < n; ++i) {
        double p[4], q[4], m = 0;
        levelsOf(x, i, p);
        levelsOf(y, i, q);
        for (int c = 0; c < 4; ++c) m = std::max(m, std::fabs(p[c] - q[c]));
        ++a.pixels;
        a.exact += m == 0;
        a.overOne += m > 1;
        a.maxDiff = std::max(a.maxDiff, m);
    }
}

bool compareFrame(Runner& reference, Runner& other, const Technique& technique, const Settings& settings, int frame,
                  int frameCount, std::vector<PassAgreement>& agreement, FrameResult& result, std::string& error,
                  const std::function<bool(PassGraph&, uint32_t, bool, std::string&)>& hook) {
    // The reference run records every pass's inputs (what it reads and what it writes, before)
    // and outputs (what it writes, after).
    std::map<uint32_t, std::vector<std::pair<uint32_t, emu::SurfacePixels>>> inputs, outputs;
    PassGraph* graph = nullptr;
    auto record = [&](uint32_t pass, bool after, std::string& e) {
        if (hook && !hook(*graph, pass, after, e)) return false;
        const PassGraph::PassNode& n = graph->passes()[pass];
        auto& store = after ? outputs[pass] : inputs[pass];
        std::vector<TextureId> ids = n.writes;
        if (!after) ids.insert(ids.end(), n.reads.begin(), n.reads.end());
        for (TextureId id : ids) {
            if (graph->texture(id).data) continue;
            std::optional<emu::SurfacePixels> px = capture(reference, *graph, id, e);
            if (!px) return false;
            store.emplace_back(id.index, std::move(*px));
        }
        return true;
    };
    if (!reference.runFrame(technique, settings, frame, frameCount, result, error, record,
                            [&](PassGraph& g) { graph = &g; }))
        return false;
    PassGraph* otherGraph = nullptr;
    auto replay = [&](uint32_t pass, bool after, std::string& e) {
        const PassGraph::PassNode& n = otherGraph->passes()[pass];
        if (!after) {
            for (auto& [id, px] : inputs[pass]) {
                emu::Handle s{};
                if (other.device().GetSurfaceLevel(otherGraph->textures()[id].device, 0, &s) != D3D_OK ||
                    !emu::writeSurface(other.device(), s, px, e))
                    return false;
            }
            return true;
        }
        auto it = std::find_if(agreement.begin(), agreement.end(), [&](const PassAgreement& a) { return a.pass == n.info.name; });
        PassAgreement& a = it != agreement.end() ? *it : agreement.emplace_back(PassAgreement{n.info.name});
        for (auto& [id, px] : outputs[pass]) {
            std::optional<emu::SurfacePixels> g = capture(other, *otherGraph, TextureId{id}, e);
            if (!g) return false;
            accumulate(a, px, *g);
        }
        return true;
    };
    FrameResult otherResult;
    if (!other.runFrame(technique, settings, frame, frameCount, otherResult, error, replay,
                        [&](PassGraph& g) { otherGraph = &g; })) {
        error = "second renderer: " + error;
        return false;
    }
    return true;
}

}  // namespace glare
