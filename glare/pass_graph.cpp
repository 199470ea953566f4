// The pass graph (glare/pass_graph.h): building (declared reads and writes), compile (culling,
// lifetimes, the read-before-write check), run (pooled textures, the device state put back
// before every pass, statistics), the declared-texture checks of PassContext, and Graphviz.
#include "glare/pass_graph.h"

#include <algorithm>
#include <chrono>
#include <set>

#include "emu/format.h"

namespace glare {

using emu::Handle;

const char* passKindName(PassKind kind) {
    switch (kind) {
        case PassKind::Shader: return "shader";
        case PassKind::FixedFunction: return "fixed-function";
        case PassKind::StretchRect: return "StretchRect";
        case PassKind::Clear: return "Clear";
        case PassKind::DeviceSide: return "device side";
    }
    return "?";
}

// ---- TexturePool ----

TexturePool::~TexturePool() {
    for (const auto& [handle, desc] : m_all) m_device.Release(Handle{handle});
}

Handle TexturePool::acquire(const TextureDesc& desc, std::string& error) {
    auto it = m_free.find(desc);
    if (it != m_free.end()) {
        const Handle h = it->second;
        m_free.erase(it);
        return h;
    }
    Handle h{};
    if (m_device.CreateTexture(desc.width, desc.height, 1, D3DUSAGE_RENDERTARGET, desc.format, D3DPOOL_DEFAULT, &h) !=
        D3D_OK) {
        error = m_device.lastError().message;
        return Handle::Null;
    }
    m_all.emplace(uint32_t(h), desc);
    return h;
}

void TexturePool::release(Handle texture) {
    auto it = m_all.find(uint32_t(texture));
    if (it != m_all.end()) m_free.emplace(it->second, texture);
}

// ---- building ----

TextureId PassBuilder::create(const std::string& name, const TextureDesc& desc) { return m_graph.create(name, desc); }

TextureId PassGraph::create(const std::string& name, const TextureDesc& desc) {
    TextureNode node;
    node.name = name;
    node.desc = desc;
    m_textures.push_back(node);
    m_compiled = false;
    return TextureId{uint32_t(m_textures.size() - 1)};
}

TextureId PassBuilder::read(TextureId texture) {
    if (!m_graph.declarable(m_pass, texture)) return texture;
    auto& reads = m_graph.m_passes[m_pass].reads;
    if (std::find(reads.begin(), reads.end(), texture) == reads.end()) reads.push_back(texture);
    return texture;
}

TextureId PassBuilder::write(TextureId texture) {
    if (!m_graph.declarable(m_pass, texture)) return texture;
    auto& writes = m_graph.m_passes[m_pass].writes;
    if (std::find(writes.begin(), writes.end(), texture) == writes.end()) writes.push_back(texture);
    return texture;
}

bool PassGraph::declarable(uint32_t pass, TextureId texture) {
    if (texture.index < m_textures.size()) return true;
    if (m_setupError.empty())
        m_setupError = "pass " + m_passes[pass].info.name + ": setup declares texture " +
                       (texture.valid() ? "#" + std::to_string(texture.index) : std::string("(invalid id)")) +
                       ", which is not a texture of this graph";
    m_compiled = false;
    return false;
}

TextureId PassGraph::createData(const std::string& name) {
    TextureNode node;
    node.name = name;
    node.desc = {0, 0, D3DFMT_UNKNOWN};
    node.data = true;
    m_textures.push_back(node);
    m_compiled = false;
    return TextureId{uint32_t(m_textures.size() - 1)};
}

TextureId PassGraph::import(const std::string& name, const TextureDesc& desc, Handle texture, bool output) {
    TextureNode node;
    node.name = name;
    node.desc = desc;
    node.imported = true;
    node.output = output;
    node.importedTexture = texture;
    m_textures.push_back(node);
    m_compiled = false;
    return TextureId{uint32_t(m_textures.size() - 1)};
}

void PassGraph::addPass(const PassInfo& info, const std::function<void(PassBuilder&)>& setup, Execute execute) {
    PassNode node;
    node.info = info;
    node.execute = std::move(execute);
    m_passes.push_back(std::move(node));
    PassBuilder builder(*this, uint32_t(m_passes.size() - 1));
    if (setup) setup(builder);
    m_compiled = false;
}

// Culling walks the passes backwards with the set of textures whose current content someone still
// needs: the outputs at the end. A pass is live when it writes a needed texture; then what it reads
// becomes needed, and what it writes without reading is no longer needed before it (it overwrote it).
// Then the live passes are walked forwards: a transient texture (or CPU data) must be written by
// an earlier live pass before a pass reads it — a pass's own write does not count, as a pass that
// declares a texture read and written keeps (blends onto) what was there.
bool PassGraph::compile() {
    std::set<uint32_t> needed;
    for (uint32_t t = 0; t < m_textures.size(); ++t)
        if (m_textures[t].output) needed.insert(t);
    for (size_t i = m_passes.size(); i-- > 0;) {
        PassNode& p = m_passes[i];
        p.live = false;
        for (TextureId w : p.writes)
            if (needed.count(w.index)) p.live = true;
        if (!p.live) continue;
        for (TextureId w : p.writes)
            if (std::find(p.reads.begin(), p.reads.end(), w) == p.reads.end()) needed.erase(w.index);
        for (TextureId r : p.reads) needed.insert(r.index);
    }
    for (TextureNode& t : m_textures) t.firstUse = t.lastUse = -1;
    for (size_t i = 0; i < m_passes.size(); ++i) {
        if (!m_passes[i].live) continue;
        auto touch = [&](TextureId id) {
            TextureNode& t = m_textures[id.index];
            if (t.firstUse < 0) t.firstUse = int(i);
            t.lastUse = int(i);
        };
        for (TextureId r : m_passes[i].reads) touch(r);
        for (TextureId w : m_passes[i].writes) touch(w);
    }
    m_compileError = m_setupError;
    std::vector<bool> written(m_textures.size(), false);
    for (const PassNode& p : m_passes) {
        if (!p.live || !m_compileError.empty()) continue;
        for (TextureId r : p.reads) {
            const TextureNode& t = m_textures[r.index];
            if (t.imported || written[r.index]) continue;
            const bool alsoWrites = std::find(p.writes.begin(), p.writes.end(), r) != p.writes.end();
            const std::string what = (t.data ? "CPU data " : "transient texture ") + t.name;
            m_compileError = alsoWrites
                                 ? "pass " + p.info.name + " reads and writes " + what +
                                       ", which no earlier live pass wrote: it would keep or blend onto undefined "
                                       "contents (a pass that clears it first declares it write() only)"
                                 : "pass " + p.info.name + " reads " + what +
                                       ", which no earlier live pass wrote: its contents are undefined";
            break;
        }
        for (TextureId w : p.writes) written[w.index] = true;
    }
    m_compiled = true;
    return m_compileError.empty();
}

std::vector<std::string> PassGraph::livePassNames() const {
    std::vector<std::string> names;
    for (const PassNode& p : m_passes)
        if (p.live) names.push_back(p.info.name);
    return names;
}

// ---- running ----

void PassMemo::clear(TexturePool& pool) {
    for (const auto& [key, handle] : m_textures) pool.release(handle);
    m_textures.clear();
    m_entries.clear();
}

size_t PassGraph::reuseGroupEnd(size_t first, bool single) const {
    // The live passes after `first` that write a texture an earlier pass of the group wrote (a
    // blur adding onto the previous pass's target) join it: skipping one of them alone would
    // leave the texture as the last of them left it, not as the first one did.
    size_t last = first;
    if (single) return last;
    std::vector<uint32_t> written;
    for (TextureId id : m_passes[first].writes) written.push_back(id.index);
    for (size_t k = first + 1; k < m_passes.size(); ++k) {
        const PassNode& p = m_passes[k];
        if (!p.live) continue;
        bool joins = false;
        for (TextureId id : p.writes) joins = joins || std::find(written.begin(), written.end(), id.index) != written.end();
        if (!joins) break;
        for (TextureId id : p.writes) written.push_back(id.index);
        last = k;
    }
    return last;
}

emu::Device::Fingerprint PassGraph::dryRun(size_t first, size_t last, emu::Device& device,
                                           const std::function<bool(const std::string&)>& putBack) {
    // One fingerprint over the group's passes, each from the graph's initial state. A pass that
    // writes CPU data (the next frame's graph holds new data objects) or has no execute step
    // makes the group run.
    bool ok = true;
    device.beginFingerprint();
    for (size_t k = first; k <= last && ok; ++k) {
        PassNode& p = m_passes[k];
        if (!p.live) continue;
        for (TextureId id : p.writes) ok = ok && !m_textures[id.index].data;
        if (!ok || !p.execute) {
            ok = false;
            break;
        }
        ok = putBack("pass " + p.info.name + ": putting back the device state");
        PassStats dryStats;
        std::string dryError;
        PassContext dry{device, dryStats, dryError, *this, uint32_t(k), {}};
        ok = ok && p.execute(dry) && dry.refusal.empty();
    }
    emu::Device::Fingerprint print = device.endFingerprint();
    print.complete = print.complete && ok;
    return print;
}

bool PassGraph::run(TexturePool& pool, std::vector<PassStats>& stats, std::string& error, const Hook& hook,
                    PassMemo* memo, bool hookObserves) {
    if (memo && memo->m_entries.size() < m_passes.size()) memo->m_entries.resize(m_passes.size());
    if (!m_compiled) compile();
    if (!m_compileError.empty()) {
        error = m_compileError;
        return false;
    }
    emu::Device& device = pool.device();
    // Every pass starts from this state, and run() leaves it behind (emu::Device::applyState).
    const emu::DeviceState initial = device.state();
    auto putBack = [&](const std::string& when) {
        if (device.applyState(initial) == D3D_OK) return true;
        error = when + ": " + device.lastError().message;
        return false;
    };
    std::map<uint32_t, int> physicalOf;  // device handle → small id, for the aliasing report
    for (TextureNode& t : m_textures) {
        t.device = t.imported ? t.importedTexture : Handle::Null;
        t.physical = -1;
    }
    // Gives every transient texture back and the device its state; the first error is kept.
    auto finish = [&](bool ok) {
        for (TextureNode& t : m_textures)
            if (!t.imported && t.device != Handle::Null) {
                if (!memo) pool.release(t.device);  // a memo's textures stay with it
                t.device = Handle::Null;
            }
        const std::string first = error;
        const bool restored = putBack("after the passes");
        if (!ok) error = first;
        return ok && restored;
    };
    // With a memo every transient texture has its own device texture, kept between frames: all
    // are bound before the first pass (a group's dry run reads its later passes' textures).
    if (memo)
        for (TextureNode& t : m_textures)
            if (!t.imported && !t.data && t.firstUse >= 0) {
                Handle& kept = memo->m_textures[{t.name, t.desc}];
                if (kept == Handle::Null) kept = pool.acquire(t.desc, error);
                if (kept == Handle::Null) {
                    error = "texture " + t.name + ": " + error;
                    return finish(false);
                }
                t.device = kept;
                auto [it, inserted] = physicalOf.emplace(uint32_t(t.device), int(physicalOf.size()));
                t.physical = it->second;
            }
    // Reuse decides for groups of passes (reuseGroup): [groupFirst, groupLast], all reused or none.
    size_t groupFirst = 0, groupLast = 0;
    bool groupReused = false;
    double groupMs = 0;
    for (size_t i = 0; i < m_passes.size(); ++i) {
        PassNode& p = m_passes[i];
        if (!p.live) continue;
        for (TextureNode& t : m_textures)
            if (!memo && !t.imported && !t.data && t.firstUse == int(i)) {
                t.device = pool.acquire(t.desc, error);
                if (t.device == Handle::Null) {
                    error = "pass " + p.info.name + ": texture " + t.name + ": " + error;
                    return finish(false);
                }
                auto [it, inserted] = physicalOf.emplace(uint32_t(t.device), int(physicalOf.size()));
                t.physical = it->second;
            }
        if (hook && !hook(uint32_t(i), false, error)) return finish(false);
        if (!putBack("pass " + p.info.name + ": putting back the device state")) return finish(false);
        PassStats s;
        s.pass = p.info.name;
        const auto start = std::chrono::steady_clock::now();
        // Reuse: at the first pass of a group, the group's calls as one dry run, compared with
        // last frame's; the group's passes are then all reused or all run.
        if (memo && (i == 0 || i > groupLast)) {
            groupFirst = i;
            groupLast = reuseGroupEnd(i, hook && !hookObserves);
            groupReused = false;
            emu::Device::Fingerprint print = dryRun(i, groupLast, device, putBack);
            PassMemo::Entry& e = memo->m_entries[i];
            std::string names;
            for (size_t k = i; k <= groupLast; ++k)
                if (m_passes[k].live) names += m_passes[k].info.name + "\n";
            bool same = print.complete && e.valid && e.name == names && e.words == print.words;
            for (const auto& [handle, generation] : e.outputs)
                same = same && device.contentGeneration(handle) == generation;
            if (!putBack("pass " + p.info.name + ": putting back the device state")) return finish(false);
            groupReused = same;
            size_t count = 0;
            for (size_t k = i; k <= groupLast; ++k) count += m_passes[k].live;
            groupMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() /
                      double(std::max<size_t>(count, 1));
            if (!same) {
                // The group runs: this dry run is next frame's reference, with the generations
                // its outputs have once the group has run (read after its last pass).
                e.name = names;
                e.valid = print.complete;
                e.words = std::move(print.words);
                e.writes = std::move(print.writes);
                e.outputs.clear();
            }
        }
        if (memo && groupReused) {
            s.reused = true;
            s.milliseconds = groupMs;  // the group's dry run, shared by its passes
            stats.push_back(s);
            if (hook && !hook(uint32_t(i), true, error)) return finish(false);
            continue;
        }
        PassContext ctx{device, s, error, *this, uint32_t(i), {}};
        const emu::TransferStats before = device.transfers();
        bool ok = p.execute ? p.execute(ctx) : true;
        if (!ctx.refusal.empty()) {
            error = ctx.refusal;
            ok = false;
        }
        device.finish();  // a renderer that queues work (GL) has done this pass's
        s.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        const emu::TransferStats after = device.transfers();
        for (const std::vector<TextureId>* list : {&p.reads, &p.writes})
            for (TextureId id : *list) {
                const TextureNode& t = m_textures[id.index];
                if (t.data) continue;
                const emu::FormatInfo* f = emu::formatInfo(t.desc.format);
                const uint64_t texel = f ? f->bytes : 4, whole = uint64_t(t.desc.width) * t.desc.height * texel;
                // A device-side step counts the pixels it looks at, not texels.
                const uint64_t touched = list == &p.reads ? (s.texels ? s.texels : s.pixels) : s.pixels;
                s.bytes += std::min(whole, touched * texel);
            }
        s.uploads = after.uploads - before.uploads;
        s.readBacks = after.readBacks - before.readBacks;
        if (!ok) {
            if (error.empty()) error = "pass " + p.info.name + " failed";
            return finish(false);
        }
        stats.push_back(s);
        if (memo && i == groupLast) {
            // The group has run: what it wrote, at the generations it left. Next frame's dry run
            // is compared with this one only while they stand.
            PassMemo::Entry& e = memo->m_entries[groupFirst];
            for (Handle h : e.writes) e.outputs.emplace_back(h, device.contentGeneration(h));
        }
        if (hook && !hook(uint32_t(i), true, error)) return finish(false);
        if (!memo)
            for (TextureNode& t : m_textures)
                if (!t.imported && t.lastUse == int(i)) {
                    pool.release(t.device);
                    t.device = Handle::Null;
                }
    }
    return finish(true);
}

bool PassContext::declared(TextureId id, Access access) const {
    const std::string& name = graph.passes()[pass].info.name;
    auto refuse = [&](const std::string& why) {
        if (refusal.empty()) refusal = "pass " + name + ": " + why;
        error = refusal;
        return false;
    };
    if (id.index >= graph.textures().size())
        return refuse("texture " + (id.valid() ? "#" + std::to_string(id.index) : std::string("(invalid id)")) +
                      " is not a texture of this graph");
    const PassGraph::PassNode& p = graph.passes()[pass];
    const bool reads = std::find(p.reads.begin(), p.reads.end(), id) != p.reads.end();
    const bool writes = std::find(p.writes.begin(), p.writes.end(), id) != p.writes.end();
    const std::string& tex = graph.texture(id).name;
    if (!reads && !writes)
        return refuse("texture " + tex + " was not declared by the pass (declare it with read() or write() in setup)");
    if (access == Access::Write && !writes)
        return refuse("texture " + tex +
                      " is written but was declared read only (declare it with write() or readWrite() in setup)");
    if (access == Access::Read && !reads)
        return refuse("texture " + tex +
                      " is read but was declared write only (declare it with read() or readWrite() in setup)");
    return true;
}

Handle PassContext::texture(TextureId id) const {
    return declared(id, Access::Any) ? graph.texture(id).device : Handle::Null;
}

Handle PassContext::surface(TextureId id) const {
    if (!declared(id, Access::Any)) return Handle::Null;
    Handle s{};
    device.GetSurfaceLevel(graph.texture(id).device, 0, &s);
    return s;
}

const TextureDesc& PassContext::desc(TextureId id) const {
    static const TextureDesc kNone{0, 0, D3DFMT_UNKNOWN};
    return declared(id, Access::Any) ? graph.texture(id).desc : kNone;
}

bool PassContext::check(HRESULT hr) {
    if (hr == D3D_OK) return true;
    error = "pass " + stats.pass + ": " + device.lastError().message;
    return false;
}

bool PassContext::setTarget(TextureId target) {
    return declared(target, Access::Write) && check(device.SetRenderTarget(0, surface(target)));
}

bool PassContext::clear(TextureId target, D3DCOLOR colour) {
    if (!setTarget(target) || !check(device.Clear(0, nullptr, D3DCLEAR_TARGET, colour, 1, 0))) return false;
    stats.pixels += uint64_t(desc(target).width) * desc(target).height;
    return true;
}

bool PassContext::stretch(TextureId source, TextureId dest, D3DTEXTUREFILTERTYPE filter) {
    if (!declared(source, Access::Read) || !declared(dest, Access::Write) ||
        !check(device.StretchRect(surface(source), nullptr, surface(dest), nullptr, filter)))
        return false;
    const uint64_t px = uint64_t(desc(dest).width) * desc(dest).height;
    stats.putOff = stats.putOff || device.lastStretchPutOff();
    stats.pixels += px;
    stats.texels += px * (filter == D3DTEXF_LINEAR ? 4 : 1);
    return true;
}

bool PassContext::draw(D3DPRIMITIVETYPE type, UINT count, const void* vertices, UINT stride) {
    if (!check(device.DrawPrimitiveUP(type, count, vertices, stride))) return false;
    const emu::DrawStats& d = device.lastDrawStats();
    stats.draws += 1;
    stats.pixels += d.pixelsCovered;
    stats.texels += d.texelsFetched;
    stats.instructions += d.instructions;
    stats.tilesShaded += d.tilesShaded;
    stats.tilesFilled += d.tilesFilled;
    stats.tilesCopied += d.tilesCopied;
    stats.tilesSkipped += d.tilesSkipped;
    return true;
}

bool PassContext::drawQuad(const std::array<emu::QuadCoords, 4>& coords, DWORD diffuse) {
    D3DVIEWPORT9 vp{};
    if (!check(device.GetViewport(&vp)) || !check(device.SetFVF(emu::kQuadFvf))) return false;
    const auto v = emu::halfPixelQuad(float(vp.X), float(vp.Y), float(vp.X + vp.Width), float(vp.Y + vp.Height), coords,
                                      diffuse);
    return draw(D3DPT_TRIANGLESTRIP, 2, v.data(), sizeof(emu::QuadVertex));
}

// ---- Graphviz ----

namespace {
std::string quoted(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"') out += '\\';  // a backslash stays: labels use \n
        out += c;
    }
    return out + "\"";
}
}  // namespace

std::string PassGraph::graphviz(const std::string& title) const {
    std::string g = "digraph " + quoted(title) + " {\n  rankdir=LR;\n  node [fontname=\"Helvetica\", fontsize=10];\n";
    for (size_t t = 0; t < m_textures.size(); ++t) {
        const TextureNode& n = m_textures[t];
        if (n.data) {
            g += "  t" + std::to_string(t) + " [shape=note, label=" + quoted(n.name + "\\n(CPU data)") + "];\n";
            continue;
        }
        std::string label = n.name + "\\n" + std::to_string(n.desc.width) + "x" + std::to_string(n.desc.height) + " " +
                            emu::formatName(n.desc.format);
        if (n.physical >= 0 && !n.imported) label += "\\ndevice texture #" + std::to_string(n.physical);
        std::string style;
        if (n.imported) style = n.firstUse < 0 ? ", style=\"filled,dashed\", fillcolor=\"#dde8f8\"" : ", style=filled, fillcolor=\"#dde8f8\"";
        else if (n.firstUse < 0) style = ", style=dashed";
        g += "  t" + std::to_string(t) + " [shape=ellipse, label=" + quoted(label) + style + "];\n";
    }
    for (size_t i = 0; i < m_passes.size(); ++i) {
        const PassNode& p = m_passes[i];
        std::string label = p.info.name + "\\n" + (p.info.kind == PassKind::Shader ? p.info.shader : passKindName(p.info.kind));
        g += "  p" + std::to_string(i) + " [shape=box, label=" + quoted(label) +
             (p.live ? (p.info.kind == PassKind::DeviceSide ? ", style=filled, fillcolor=\"#f8dddd\"" : "")
                     : ", style=dashed, fontcolor=gray") +
             "];\n";
        for (TextureId r : p.reads) g += "  t" + std::to_string(r.index) + " -> p" + std::to_string(i) + ";\n";
        for (TextureId w : p.writes) g += "  p" + std::to_string(i) + " -> t" + std::to_string(w.index) + ";\n";
    }
    return g + "}\n";
}

}  // namespace glare
