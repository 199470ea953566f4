// Device front: fingerprints (emu/device.h, docs/device.md "Fingerprints"), what lets a caller
// know, without running them, that a series of calls would write what it wrote last time.
#include <algorithm>
#include <cstring>

#include "emu/device.h"

namespace emu {

void Device::beginFingerprint() {
    m_fingerprint = FingerprintState{};
    m_fingerprint.active = true;
    m_fingerprint.print.complete = true;
    // Room for a pass's draw or two (each takes the whole state): one allocation, not a dozen.
    m_fingerprint.print.words.reserve(2 * m_state.wordCount() + 256);
}

Device::Fingerprint Device::endFingerprint() {
    Fingerprint f = std::move(m_fingerprint.print);
    f.complete = f.complete && m_fingerprint.active;
    m_fingerprint = FingerprintState{};
    return f;
}

Handle Device::ownerOf(Handle h) const {
    auto s = m_surfaces.find(uint32_t(h));
    return s != m_surfaces.end() ? s->second.owner : h;
}

uint64_t Device::contentGeneration(Handle h) const {
    auto r = m_resources.find(uint32_t(ownerOf(h)));
    return r == m_resources.end() ? 0 : r->second.generation;
}

void Device::fingerprintWords(const void* data, size_t bytes) {
    std::vector<uint32_t>& w = m_fingerprint.print.words;
    const size_t at = w.size();
    w.resize(at + (bytes + 3) / 4, 0);
    if (bytes) std::memcpy(w.data() + at, data, bytes);
}

void Device::fingerprintRead(Handle owner) {
    if (owner == Handle::Null) return;
    const std::vector<Handle>& d = m_fingerprint.determined;
    if (std::find(d.begin(), d.end(), owner) != d.end()) return;  // written whole by an earlier call
    // A renderer that keeps copies writes where the front cannot compare, so every write of its
    // makes a new generation: a small resource is read by its bytes instead (brought back first),
    // and a write that changed none of them reads as the same (a converged 1×1 adaptation state).
    auto it = m_resources.find(uint32_t(owner));
    if (it != m_resources.end() && m_renderer->keepsCopies() && resourceLevelBytes(it->second) <= kComparedResourceBytes) {
        Resource& r = it->second;
        syncResource(r);
        const uint32_t head[4] = {uint32_t(owner), ~0u, ~0u, uint32_t(resourceLevelBytes(r))};  // no generation is 2⁶⁴ − 1
        fingerprintWords(head, sizeof head);
        for (const Image& im : r.levels) fingerprintWords(im.bytes.data(), levelBytes(im));
        return;
    }
    const uint64_t g = contentGeneration(owner);
    const uint32_t words[3] = {uint32_t(owner), uint32_t(g), uint32_t(g >> 32)};
    fingerprintWords(words, sizeof words);
}

void Device::fingerprintWrite(Handle owner, bool wholeImage) {
    if (owner == Handle::Null) return;
    std::vector<Handle>& w = m_fingerprint.print.writes;
    if (std::find(w.begin(), w.end(), owner) == w.end()) w.push_back(owner);
    std::vector<Handle>& d = m_fingerprint.determined;
    if (wholeImage && std::find(d.begin(), d.end(), owner) == d.end()) d.push_back(owner);
}

HRESULT Device::fingerprintRefuse(const char* call) {
    m_fingerprint.print.complete = false;
    return fail(D3DERR_INVALIDCALL, "E4125",
                std::string(call) + ": hands contents back to the caller, which a fingerprint cannot defer "
                                    "(Device::beginFingerprint)");
}

}  // namespace emu
