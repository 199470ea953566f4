// Glare sprites (Ando, Torigoe, Toriyama, Ichimiya, GRAPP 2006): GLARE.md §5,
// docs/glare/sprites.md. The sensor step (vertex texture fetch in the paper: vs_3_0, not 1.1)
// runs on the device side; its grouping is exposed here for tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace emu {
class ThreadPool;
}

namespace glare {

struct Sprite {
    float x = 0, y = 0;           // centre, in pixels (pixel centres at integers)
    float energy[3] = {0, 0, 0};  // Σ of the sensors' colours × strength, per channel
    float radius = 0;             // half the quad's side, in pixels
    bool cluster = false;
};

struct SensorSettings {
    float threshold = 0.8f;  // a sensor fires where luminance (0.30, 0.59, 0.11) >= threshold
    int group = 1;           // N: each N x N block of pixels gives at most one sprite
    bool clusters = true;    // an 8x8 block >= 90 % bright gives one cluster sprite, the others none
    float strength = 0.25f;  // the glare image's peak per unit of pixel colour
    float radius = 32;       // sprite radius in pixels (cluster sprites: twice)
    bool operator==(const SensorSettings&) const = default;
};

// A frame of 8-bit pixels for the sensors: rows top to bottom, `pitch` bytes apart, 4 bytes a
// pixel in r g b a order, or b g r a (D3D's A8R8G8B8 and X8R8G8B8 as they sit in memory).
struct SensorFrame {
    const uint8_t* data = nullptr;
    uint32_t width = 0, height = 0;
    size_t pitch = 0;
    bool bgra = false;
    // The workers for the frame's bands (null: the calling thread alone). At most 8 bands, and
    // never more than bands of 64 rows; the sprites do not depend on it.
    emu::ThreadPool* pool = nullptr;
    // Or a frame of floats, r g b a (a float render target; `data` and `bgra` unused): the
    // sensors see each value as frameByte makes it a byte, the 8-bit frame readTexture gives.
    // Each row is converted where the sensors read it, and kept only where a sensor fires (the
    // only pixels read again), so no 8-bit copy of the frame is written.
    const float* values = nullptr;
};

// The least float s with s / 255.0f >= threshold (a float division): a sensor's luminance, the
// sum 0.30·r + 0.59·g + 0.11·b (bytes, float arithmetic in that order) over 255, reaches the
// threshold exactly where the sum reaches s, since the division rounds monotonically; the sensors
// compare sums and never divide. A NaN threshold gives +inf (never fires), one <= 0 gives −inf.
float sensorSumThreshold(float threshold);

// The sprites of a frame. Grouping: a group's sprite sits
// at the luminance-weighted centre of its firing pixels, Σ L_i p_i / Σ L_i, and carries the sum of
// their colours, so its energy equals that of the N² single-pixel sprites it replaces. A cluster
// sprite has twice the radius (four times the area) and carries the same sum.
std::vector<Sprite> senseSprites(const SensorFrame& frame, const SensorSettings& s);
// The same over tight rgba rows.
std::vector<Sprite> senseSprites(const uint8_t* rgba, uint32_t width, uint32_t height, const SensorSettings& s);

// The glare image (size x size, values in [0, 1], peak 1 at the centre): radial streaks plus a halo.
std::vector<float> glareImage(uint32_t size, int streaks);

}  // namespace glare
