// The built-in procedural 3D scenes the glare techniques run on (docs/glare/scenes.md): `box`
// (eye adaptation: a camera path from inside a dark box out into daylight), `neon` (glow masks:
// emissive strips in alpha over bright but non-glowing objects), `lights` (sparse point lights at
// night, some exactly one pixel, moving by sub-pixel steps) and `sky` (a large bright area).
// Each frame is drawn through emu::Device's D3D9-style API only (GLM transforms, fixed-function
// stages, DrawPrimitiveUP), so it draws the same on the software and the GL renderer.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "emu/device.h"

namespace glare {

struct SceneInfo {
    std::string_view name, description;
    int defaultFrames;  // the animation's length when the caller names none
};

// box, neon, lights, sky, sparse, dense (in that order).
const std::vector<SceneInfo>& sceneList();

class Scene {
public:
    virtual ~Scene() = default;
    // Draws frame `frame` (0 … frameCount − 1) of the scene's animation into `target`, an
    // A8R8G8B8 render target surface of `device` (any size; the aspect ratio comes from the
    // surface). RGB is the scene; alpha is the glow mask: 255 on emissive surfaces (lights, neon
    // strips, bright objects, the sun), 0 elsewhere. Device resources (a D24S8 depth surface of
    // the target's size) are made on first use and reused; a target of another size gets a new
    // one. The whole device state is put back as it was afterwards, failed or not
    // (emu::Device::applyState).
    // A Scene serves one device at a time (its depth surface belongs to that device).
    // False with `error` set ("scene box: Device::DrawPrimitiveUP failed: <device message>",
    // "scene box: frame 7 out of range 0..3", …) on failure.
    virtual bool render(emu::Device& device, emu::Handle target, int frame, int frameCount, std::string& error) = 0;
    // Glow-only black fog (James & O'Rorke): the glow mask (alpha) of every vertex is scaled by
    // D3D's linear fog factor (end − d)/(end − start), clamped to [0, 1], d its distance from the
    // camera in scene units, so distant glow sources fade while the scene's colours stay as they
    // are. end <= start: off (the default).
    void setGlowFog(float start, float end) {
        m_glowFogStart = start;
        m_glowFogEnd = end;
    }

protected:
    float m_glowFogStart = 0, m_glowFogEnd = 0;
};

// The scene named `name` (see sceneList), or nullptr with `error` =
// "unknown scene 'x' (scenes: box, neon, lights, sky)".
std::unique_ptr<Scene> makeScene(std::string_view name, std::string& error);

}  // namespace glare
