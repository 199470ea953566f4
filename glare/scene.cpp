// The built-in procedural scenes (glare/scene.h, docs/glare/scenes.md). Geometry is built on the
// CPU each frame in world space (a few hundred triangles) and lit per vertex on the CPU (the
// device has no vertex lighting: Lambert with a directional light, ambient and point lights).
// Each scene is drawn as painter's layers that need no depth test: their triangles are
// transformed with the camera's GLM matrices, clipped and projected here and drawn as XYZRHW
// screen triangles, 16 a draw (the software device's fast row path); flat ground and night sky
// are Clears above and below the horizon. Objects that may hide each other (box) go through the
// device's own World · View · Projection with a D24S8 depth buffer cleared over their screen
// rectangles only. The fixed-function stage 0 selects the diffuse colour and alpha, so vertex
// alpha is the glow mask.
#include "glare/scene.h"

#include "glare/scene_kit.h"

namespace glare {
namespace {

using namespace emu;
using namespace scene_kit;

// ---- box: eye adaptation ----
//
// An open box (x −2…2, y 0.1…2.5, z 0…4 inside, walls 0.1 thick, open towards −z) with three
// emissive objects, on a mid-grey tiled ground under a bright sky. The camera starts inside,
// looking at the objects, and backs out through the opening to 13 units in front of the box.
class BoxScene final : public SceneBase {
public:
    BoxScene() : SceneBase("box") {}

protected:
    bool draw(int frame, int frameCount) override {
        const float t = frameCount > 1 ? float(frame) / float(frameCount - 1) : 0.0f;
        const float s = smoothstep01(t);
        const glm::vec3 eye = glm::mix(glm::vec3(0.35f, 1.3f, 0.6f), glm::vec3(2.6f, 3.3f, -13.0f), s);
        const glm::vec3 at = glm::mix(glm::vec3(0.0f, 1.05f, 4.0f), glm::vec3(0.0f, 1.3f, 2.0f), s);
        if (!camera(eye, at, 60.0f, 0.05f, 1500.0f)) return false;

        // The emissive objects, turning slowly.
        struct Object {
            glm::vec3 position, rgb;
        };
        const float spin = 2.0f * kPi * t;
        const Object objects[3] = {{{-1.05f, 0.5f, 2.9f}, {1.0f, 0.2f, 0.1f}},
                                   {{0.95f, 1.0f + 0.1f * std::sin(spin), 2.7f}, {0.2f, 1.0f, 0.3f}},
                                   {{0.05f, 1.0f, 3.5f}, {0.3f, 0.5f, 1.0f}}};
        const glm::vec3 toSun = glm::normalize(glm::vec3(-0.4f, 1.0f, -0.5f));
        std::array<Mesh, 3> mesh;
        mesh[0].emissiveCube(glm::rotate(glm::translate(glm::mat4(1.0f), objects[0].position), 0.6f + spin * 0.5f,
                                      glm::vec3(0, 1, 0)),
                          0.38f, objects[0].rgb, toSun);
        mesh[1].emissiveOctahedron(glm::rotate(glm::translate(glm::mat4(1.0f), objects[1].position), spin,
                                            glm::vec3(0, 1, 0)),
                                0.5f, objects[1].rgb, toSun);
        mesh[2].emissivePrism(glm::rotate(glm::translate(glm::mat4(1.0f), objects[2].position), -spin * 0.5f,
                                       glm::vec3(0, 1, 0)),
                           0.28f, 1.8f, 6, objects[2].rgb, toSun);

        // Inside: a little ambient and the objects' light; outside: sun and sky.
        Lighting inside;
        inside.ambient = glm::vec3(0.05f);
        for (const Object& o : objects) inside.points.push_back({o.position, o.rgb * 1.3f, 0.9f});
        Lighting outside;
        outside.ambient = glm::vec3(0.36f, 0.38f, 0.44f);
        outside.sunDirection = -toSun;
        outside.sunColor = glm::vec3(0.72f, 0.68f, 0.6f);

        // The ground: 4-unit tiles around the box, then four large quads to the horizon.
        Mesh ground;
        const glm::vec3 up(0, 1, 0);
        for (int i = -6; i < 6; ++i)
            for (int j = -6; j < 6; ++j) {
                const float x0 = float(i) * 4.0f, z0 = float(j) * 4.0f;
                const glm::vec3 albedo((i + j) & 1 ? 0.5f : 0.56f);
                ground.litQuad({glm::vec3(x0, 0, z0), glm::vec3(x0 + 4, 0, z0), glm::vec3(x0 + 4, 0, z0 + 4),
                                glm::vec3(x0, 0, z0 + 4)},
                               up, albedo, outside, 1, 1);
            }
        const float r = 24.0f, far = 900.0f;
        const glm::vec3 g(0.53f);
        ground.litQuad({glm::vec3(-far, 0, -far), glm::vec3(far, 0, -far), glm::vec3(far, 0, -r), glm::vec3(-far, 0, -r)},
                       up, g, outside, 1, 1);
        ground.litQuad({glm::vec3(-far, 0, r), glm::vec3(far, 0, r), glm::vec3(far, 0, far), glm::vec3(-far, 0, far)},
                       up, g, outside, 1, 1);
        ground.litQuad({glm::vec3(-far, 0, -r), glm::vec3(-r, 0, -r), glm::vec3(-r, 0, r), glm::vec3(-far, 0, r)}, up,
                       g, outside, 1, 1);
        ground.litQuad({glm::vec3(r, 0, -r), glm::vec3(far, 0, -r), glm::vec3(far, 0, r), glm::vec3(r, 0, r)}, up, g,
                       outside, 1, 1);

        // The box's inner faces (x −2…2, y 0.1…2.5, z 0…4; lit by the objects) and its outer
        // faces (the convex hull x −2.1…2.1, y 0…2.6, z 0…4.1 less the opening; lit by the sun).
        const glm::vec3 wall(0.42f, 0.4f, 0.38f), exterior(0.2f, 0.19f, 0.18f);
        Mesh inner, outer;
        const float x0 = -2.0f, x1 = 2.0f, y0 = 0.1f, y1 = 2.5f, z1 = 4.0f, X0 = -2.1f, X1 = 2.1f, Y1 = 2.6f, Z1 = 4.1f;
        inner.litQuad({glm::vec3(x0, y0, 0), glm::vec3(x1, y0, 0), glm::vec3(x1, y0, z1), glm::vec3(x0, y0, z1)},
                      {0, 1, 0}, wall, inside, 5, 5);
        inner.litQuad({glm::vec3(x0, y1, 0), glm::vec3(x1, y1, 0), glm::vec3(x1, y1, z1), glm::vec3(x0, y1, z1)},
                      {0, -1, 0}, wall, inside, 5, 5);
        inner.litQuad({glm::vec3(x0, y0, 0), glm::vec3(x0, y0, z1), glm::vec3(x0, y1, z1), glm::vec3(x0, y1, 0)},
                      {1, 0, 0}, wall, inside, 5, 3);
        inner.litQuad({glm::vec3(x1, y0, 0), glm::vec3(x1, y0, z1), glm::vec3(x1, y1, z1), glm::vec3(x1, y1, 0)},
                      {-1, 0, 0}, wall, inside, 5, 3);
        inner.litQuad({glm::vec3(x0, y0, z1), glm::vec3(x1, y0, z1), glm::vec3(x1, y1, z1), glm::vec3(x0, y1, z1)},
                      {0, 0, -1}, wall, inside, 5, 3);
        outer.litQuad({glm::vec3(X0, 0, 0), glm::vec3(X0, 0, Z1), glm::vec3(X0, Y1, Z1), glm::vec3(X0, Y1, 0)},
                      {-1, 0, 0}, exterior, outside, 1, 1);
        outer.litQuad({glm::vec3(X1, 0, 0), glm::vec3(X1, 0, Z1), glm::vec3(X1, Y1, Z1), glm::vec3(X1, Y1, 0)},
                      {1, 0, 0}, exterior, outside, 1, 1);
        outer.litQuad({glm::vec3(X0, Y1, 0), glm::vec3(X1, Y1, 0), glm::vec3(X1, Y1, Z1), glm::vec3(X0, Y1, Z1)},
                      {0, 1, 0}, exterior, outside, 1, 1);
        outer.litQuad({glm::vec3(X0, 0, Z1), glm::vec3(X1, 0, Z1), glm::vec3(X1, Y1, Z1), glm::vec3(X0, Y1, Z1)},
                      {0, 0, 1}, exterior, outside, 1, 1);
        // The rim around the opening (plane z = 0).
        const glm::vec3 front(0, 0, -1);
        outer.litQuad({glm::vec3(X0, 0, 0), glm::vec3(X1, 0, 0), glm::vec3(X1, y0, 0), glm::vec3(X0, y0, 0)}, front,
                      exterior, outside, 1, 1);
        outer.litQuad({glm::vec3(X0, y1, 0), glm::vec3(X1, y1, 0), glm::vec3(X1, Y1, 0), glm::vec3(X0, Y1, 0)}, front,
                      exterior, outside, 1, 1);
        outer.litQuad({glm::vec3(X0, y0, 0), glm::vec3(x0, y0, 0), glm::vec3(x0, y1, 0), glm::vec3(X0, y1, 0)}, front,
                      exterior, outside, 1, 1);
        outer.litQuad({glm::vec3(x1, y0, 0), glm::vec3(X1, y0, 0), glm::vec3(X1, y1, 0), glm::vec3(x1, y1, 0)}, front,
                      exterior, outside, 1, 1);

        // From inside the box the world outside shows only through the opening (z = 0).
        const bool eyeInside = eye.x > x0 && eye.x < x1 && eye.y > y0 && eye.y < y1 && eye.z > 0.0f && eye.z < z1;
        Mesh opening;
        opening.flatQuad({glm::vec3(x0, y0, 0), glm::vec3(x1, y0, 0), glm::vec3(x1, y1, 0), glm::vec3(x0, y1, 0)},
                         {0, 0, 1}, 0);
        const bool seesOut = !eyeInside || !toScreen(opening).empty();

        // Painter's layers: sky (down to a little below the horizon: the ground's far edge),
        // ground, the box's inside, the objects (depth-tested among themselves), the box's outside
        // (its visible faces hide everything inside).
        if (seesOut && (!drawSky(eye,
                                 {{-10.0f, {0.86f, 0.89f, 0.93f}},
                                  {0.0f, {0.86f, 0.89f, 0.93f}},
                                  {12.0f, {0.74f, 0.82f, 0.92f}},
                                  {35.0f, {0.58f, 0.7f, 0.88f}},
                                  {90.0f, {0.45f, 0.6f, 0.85f}}},
                                 0.02) ||
                        !drawMesh(ground)))
            return false;
        return drawMesh(inner) && drawObjects(mesh) && drawMesh(outer);
    }
};

// ---- neon: glow masks ----
//
// A dark wall (z = 6) and floor with neon strips in five colours (alpha 255) and bright, lit,
// non-glowing objects (alpha 0): a pedestal, a sphere, a column and a pale poster on the wall.
// The strips pulse (each with its own phase) and the camera sways; the loop is seamless.
class NeonScene final : public SceneBase {
public:
    NeonScene() : SceneBase("neon") {}

protected:
    bool draw(int frame, int frameCount) override {
        const float t = float(frame) / float(frameCount);
        const float sway = std::sin(2.0f * kPi * t);
        if (!camera({0.7f * sway, 1.7f, -3.0f}, {0.3f * sway, 2.6f, 6.0f}, 55.0f, 0.1f, 100.0f)) return false;

        Lighting light;
        light.ambient = glm::vec3(0.14f, 0.13f, 0.16f);
        light.sunDirection = glm::normalize(glm::vec3(0.35f, -0.55f, 1.0f));
        light.sunColor = glm::vec3(0.95f, 0.92f, 0.86f);

        Mesh shell, decor;  // painter's layers: the room, then what is on the wall
        std::array<Mesh, 3> objects;  // then the objects
        const glm::vec3 dark(0.1f, 0.09f, 0.12f);
        shell.litQuad({glm::vec3(-10, 0, 6), glm::vec3(10, 0, 6), glm::vec3(10, 9, 6), glm::vec3(-10, 9, 6)}, {0, 0, -1},
                     dark, light, 1, 1);
        shell.litQuad({glm::vec3(-10, 0, -6), glm::vec3(10, 0, -6), glm::vec3(10, 0, 6), glm::vec3(-10, 0, 6)}, {0, 1, 0},
                     glm::vec3(0.09f, 0.09f, 0.1f), light, 1, 1);
        shell.litQuad({glm::vec3(-10, 0, -6), glm::vec3(-10, 0, 6), glm::vec3(-10, 9, 6), glm::vec3(-10, 9, -6)},
                     {1, 0, 0}, dark, light, 1, 1);
        shell.litQuad({glm::vec3(10, 0, -6), glm::vec3(10, 0, 6), glm::vec3(10, 9, 6), glm::vec3(10, 9, -6)}, {-1, 0, 0},
                     dark, light, 1, 1);

        // Bright diffuse objects (alpha 0).
        objects[0].litBox({-4.2f, 0.0f, 2.4f}, {-2.4f, 1.4f, 4.2f}, 10.0f, uniform({0.9f, 0.88f, 0.84f}, light), false);
        objects[1].litBox({3.0f, 0.0f, 3.2f}, {3.9f, 3.6f, 4.1f}, 10.0f, uniform({0.86f, 0.87f, 0.9f}, light), false);
        objects[2].litSphere({0.6f, 1.0f, 3.0f}, 0.95f, 16, 9, glm::vec3(0.95f, 0.93f, 0.9f), light);
        decor.litQuad({glm::vec3(-1.6f, 3.4f, 5.98f), glm::vec3(1.1f, 3.4f, 5.98f), glm::vec3(1.1f, 5.0f, 5.98f),
                      glm::vec3(-1.6f, 5.0f, 5.98f)},
                     {0, 0, -1}, glm::vec3(0.9f, 0.86f, 0.72f), light, 1, 1);

        // Neon strips (alpha 255), each pulsing between 82 % and 100 %.
        const float z = 5.95f, w = 0.08f;
        int index = 0;
        auto neon = [&](glm::vec3 rgb) {
            const float phase = noise(17, uint32_t(index++));
            return packColor(rgb * (0.91f + 0.09f * std::sin(2.0f * kPi * (t + phase))), true);
        };
        const glm::vec3 pink(1.0f, 0.16f, 0.78f), cyan(0.16f, 0.9f, 1.0f), green(0.22f, 1.0f, 0.3f),
            orange(1.0f, 0.6f, 0.08f), blue(0.25f, 0.42f, 1.0f);
        {  // a pink frame
            const DWORD c = neon(pink);
            const glm::vec2 p[4] = {{-6.6f, 2.2f}, {-3.4f, 2.2f}, {-3.4f, 4.7f}, {-6.6f, 4.7f}};
            for (int i = 0; i < 4; ++i) decor.strip(p[i], p[(i + 1) % 4], z, w, c);
        }
        for (float y : {5.6f, 5.85f}) decor.strip({-3.0f, y}, {3.0f, y}, z, w, neon(cyan));  // two cyan lines
        {  // a green zigzag
            const DWORD c = neon(green);
            for (int i = 0; i < 6; ++i)
                decor.strip({1.8f + 0.8f * float(i), (i & 1) ? 3.1f : 2.1f},
                           {1.8f + 0.8f * float(i + 1), (i & 1) ? 2.1f : 3.1f}, z, w, c);
        }
        for (float x : {-8.0f, 8.0f}) decor.strip({x, 0.6f}, {x, 5.4f}, z, w, neon(orange));  // orange bars
        {  // a blue wave
            const DWORD c = neon(blue);
            auto wave = [](float x) { return glm::vec2(x, 2.0f + 0.3f * std::sin(x * 2.5f)); };
            for (int i = 0; i < 16; ++i)
                decor.strip(wave(-2.5f + 5.0f * float(i) / 16.0f), wave(-2.5f + 5.0f * float(i + 1) / 16.0f), z, w, c);
        }
        {  // a pink ring
            const DWORD c = neon(pink);
            for (int i = 0; i < 24; ++i) {
                const float a0 = 2.0f * kPi * float(i) / 24.0f, a1 = 2.0f * kPi * float(i + 1) / 24.0f;
                decor.strip({5.2f + 0.8f * std::cos(a0), 5.0f + 0.8f * std::sin(a0)},
                           {5.2f + 0.8f * std::cos(a1), 5.0f + 0.8f * std::sin(a1)}, z, w, c);
            }
        }
        // The objects are convex and apart: drawn far to near (by their centres), no depth needed.
        const glm::vec3 eye(0.7f * sway, 1.7f, -3.0f);
        const std::array<glm::vec3, 3> centres = {glm::vec3(-3.3f, 0.7f, 3.3f), glm::vec3(3.45f, 1.8f, 3.65f),
                                                  glm::vec3(0.6f, 1.0f, 3.0f)};
        std::array<int, 3> order = {0, 1, 2};
        std::sort(order.begin(), order.end(), [&](int a, int b) {
            return glm::length(centres[size_t(a)] - eye) > glm::length(centres[size_t(b)] - eye);
        });
        Mesh near;
        for (int k : order)
            near.vertices.insert(near.vertices.end(), objects[size_t(k)].vertices.begin(), objects[size_t(k)].vertices.end());
        return drawMesh(shell) && drawMesh(decor) && drawMesh(near);
    }
};

// ---- lights: sparse point lights at night ----
//
// A dark city of 49 blocks seen from above; street lights, lit windows and red roof beacons are
// projected on the CPU and drawn as screen squares of whole pixels (1 to 5 at 1080p by distance,
// scaled with the target's height, at least 1), depth-tested against the buildings. The camera
// drifts sideways 0.01 units a frame (about a quarter pixel at 1080p for lights 40 units away).
class LightsScene final : public SceneBase {
public:
    LightsScene() : SceneBase("lights") {}

protected:
    D3DCOLOR clearColor() const override { return 0x0003050C; }  // night sky, alpha 0

    bool draw(int frame, int frameCount) override {
        const float step = std::min(0.01f, 4.0f / float(frameCount));
        const float drift = (float(frame) - float(frameCount - 1) / 2.0f) * step;
        const glm::vec3 eye(drift, 16.0f, -22.0f);
        if (!camera(eye, eye + glm::vec3(0.0f, -16.0f, 62.0f), 50.0f, 1.0f, 1000.0f)) return false;

        Lighting moon;
        moon.ambient = glm::vec3(0.1f, 0.11f, 0.17f);
        moon.sunDirection = glm::normalize(glm::vec3(-0.3f, -1.0f, 0.4f));
        moon.sunColor = glm::vec3(0.22f, 0.24f, 0.32f);

        struct Light {
            glm::vec3 position, rgb;
            float k;        // size in pixels at 1080p = k / distance, rounded
            int maxPixels;  // at 1080p
        };
        std::vector<Light> lights;
        struct Building {
            glm::vec3 lo, hi;
            float grey;
            int row;
        };
        std::vector<Building> buildings;
        for (int i = -3; i <= 3; ++i)
            for (int j = 0; j < 7; ++j) {
                const uint32_t id = uint32_t((i + 3) * 7 + j);
                const glm::vec3 centre(float(i) * 9.0f + (noise(1, id) - 0.5f) * 1.5f, 0.0f,
                                       10.0f + float(j) * 10.0f + (noise(2, id) - 0.5f) * 1.5f);
                const float wx = 3.5f + 2.5f * noise(3, id), wz = 3.5f + 2.5f * noise(4, id);
                const float h = 3.0f + 14.0f * noise(5, id) * noise(5, id);
                const glm::vec3 lo = centre - glm::vec3(wx / 2, 0, wz / 2), hi = centre + glm::vec3(wx / 2, h, wz / 2);
                const float grey = 0.1f + 0.05f * noise(6, id);
                buildings.push_back({lo, hi, grey, j});
                // Lit windows on the face towards the camera (−z) and on one side.
                const int windows = int(noise(7, id) * 4.0f);
                for (int k = 0; k < windows; ++k) {
                    const float u = noise(8, id, uint32_t(k)), v = 0.15f + 0.75f * noise(9, id, uint32_t(k));
                    const bool warm = noise(10, id, uint32_t(k)) < 0.7f;
                    const glm::vec3 rgb = warm ? glm::vec3(1.0f, 0.88f, 0.62f) : glm::vec3(0.78f, 0.88f, 1.0f);
                    glm::vec3 p;
                    if (k & 1)
                        p = {i <= 0 ? hi.x + 0.05f : lo.x - 0.05f, v * h, lo.z + (0.1f + 0.8f * u) * wz};
                    else
                        p = {lo.x + (0.1f + 0.8f * u) * wx, v * h, lo.z - 0.05f};
                    lights.push_back({p, rgb, 45.0f, 2});
                }
                if (h > 12.0f) lights.push_back({{centre.x, h + 0.3f, centre.z}, {1.0f, 0.12f, 0.08f}, 60.0f, 3});
            }
        // Street lights along the streets between the blocks, both ways.
        const glm::vec3 sodium(1.0f, 0.72f, 0.36f);
        for (int i = -4; i <= 3; ++i)
            for (int k = 0; k < 13; ++k)
                lights.push_back({{(float(i) + 0.5f) * 9.0f, 0.6f, 2.0f + 6.0f * float(k)}, sodium, 140.0f, 5});
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 10; ++k)
                lights.push_back({{-31.5f + 7.0f * float(k), 0.6f, 5.0f + 10.0f * float(j)}, sodium, 140.0f, 5});

        // Painter's order, exact for this layout (rows and columns apart, the camera in front of
        // the first row and within the middle column): far rows first, in a row the buildings
        // farthest to the side first.
        std::stable_sort(buildings.begin(), buildings.end(), [&](const Building& a, const Building& b) {
            if (a.row != b.row) return a.row > b.row;
            return std::abs((a.lo.x + a.hi.x) / 2 - eye.x) > std::abs((b.lo.x + b.hi.x) / 2 - eye.x);
        });
        Mesh city;
        for (const Building& b : buildings) city.litBox(b.lo, b.hi, 100.0f, uniform({b.grey, b.grey, 0.13f}, moon), false);
        // The ground (lit by the moon alone: one colour) and the sky are Clears above and below
        // the horizon.
        const DWORD ground = packColor(moon.shade(glm::vec3(0.07f, 0.07f, 0.08f), eye, {0, 1, 0}), false);
        if (!clearSkyAndGround(clearColor(), ground) || !drawMesh(city)) return false;

        // The lights as squares of whole pixels around their projected centres, over everything;
        // a light whose line of sight crosses a building is hidden (tested on the CPU).
        auto hidden = [&](glm::vec3 p) {
            const glm::vec3 d = p - eye;
            for (const Building& b : buildings) {
                float t0 = 0.0f, t1 = 1.0f;
                for (int axis = 0; axis < 3 && t0 <= t1; ++axis) {
                    if (std::abs(d[axis]) < 1e-9f) {
                        if (eye[axis] < b.lo[axis] || eye[axis] > b.hi[axis]) t0 = 2.0f;
                        continue;
                    }
                    float ta = (b.lo[axis] - eye[axis]) / d[axis], tb = (b.hi[axis] - eye[axis]) / d[axis];
                    if (ta > tb) std::swap(ta, tb);
                    t0 = std::max(t0, ta);
                    t1 = std::min(t1, tb);
                }
                if (t0 <= t1) return true;
            }
            return false;
        };
        std::vector<ScreenVertex> quads;
        const float scale = float(height()) / 1080.0f;
        for (const Light& l : lights) {
            glm::dvec4 s;
            if (!project(l.position, s) || hidden(l.position)) continue;
            const float distance = glm::length(l.position - eye);
            const float at1080 = std::clamp(std::round(l.k / distance), 1.0f, float(l.maxPixels));
            const float size = std::max(1.0f, std::round(at1080 * scale));
            const float x0 = float(s.x) - size / 2, y0 = float(s.y) - size / 2;
            if (x0 + size < -1.0f || y0 + size < -1.0f || x0 > float(width()) + 1.0f || y0 > float(height()) + 1.0f)
                continue;
            const DWORD c = packColor(l.rgb, true);
            const float z = float(s.z), rhw = float(s.w);
            const ScreenVertex a{x0, y0, z, rhw, c}, b{x0 + size, y0, z, rhw, c}, cc{x0 + size, y0 + size, z, rhw, c},
                d{x0, y0 + size, z, rhw, c};
            quads.insert(quads.end(), {a, b, cc, a, cc, d});
        }
        return drawScreen(quads);
    }
};

// ---- sky: a large bright area ----
//
// A bright sky dome (every part above 0.8 luminance) with a saturated sun disc over darker
// ground, a ring of distant mountains and a few standing stones; the camera pans ±6° and back.
class SkyScene final : public SceneBase {
public:
    SkyScene() : SceneBase("sky") {}

protected:
    bool draw(int frame, int frameCount) override {
        const float t = float(frame) / float(frameCount);
        const float yaw = (8.0f + 6.0f * std::sin(2.0f * kPi * t)) * kPi / 180.0f, pitch = 8.0f * kPi / 180.0f;
        const glm::vec3 eye(0.0f, 1.7f, 0.0f);
        const glm::vec3 forward(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
        if (!camera(eye, eye + forward, 60.0f, 0.2f, 3000.0f)) return false;

        const glm::vec3 toSun = glm::normalize(glm::vec3(0.35f, 0.42f, 1.0f));
        Lighting day;
        day.ambient = glm::vec3(0.55f, 0.57f, 0.62f);
        day.sunDirection = -toSun;
        day.sunColor = glm::vec3(0.75f, 0.7f, 0.6f);

        Mesh mountains, sun;
        // Mountains: a ridge of 40 peaks at 600 units, foot at 640.
        const int peaks = 40;
        auto ridge = [&](int i, float radius, float y) {
            const float a = 2.0f * kPi * float(i) / float(peaks);
            return glm::vec3(radius * std::sin(a), y, radius * std::cos(a));
        };
        for (int i = 0; i < peaks; ++i) {
            const int j = i + 1;
            const float h0 = 20.0f + 60.0f * noise(20, uint32_t(i % peaks)), h1 = 20.0f + 60.0f * noise(20, uint32_t(j % peaks));
            const glm::vec3 a = ridge(i, 640.0f, -1.0f), b = ridge(j, 640.0f, -1.0f), c = ridge(j, 600.0f, h1),
                            d = ridge(i, 600.0f, h0);
            const glm::vec3 n = glm::normalize(glm::cross(b - a, d - a));
            const glm::vec3 facing = glm::dot(n, -a) > 0 ? n : -n;
            mountains.litQuad({a, b, c, d}, facing, glm::vec3(0.3f, 0.32f, 0.38f), day, 1, 1);
        }
        // Standing stones, drawn far to near.
        std::array<Mesh, 10> stones;
        std::array<std::pair<float, uint32_t>, 10> order;
        for (uint32_t k = 0; k < 10; ++k) {
            const float a = (noise(21, k) - 0.5f) * 1.6f, r = 15.0f + 45.0f * noise(22, k);
            const glm::vec3 c(r * std::sin(a), 0.0f, r * std::cos(a));
            const float w = 0.6f + 0.8f * noise(23, k), h = 1.0f + 3.0f * noise(24, k);
            stones[k].litBox(c - glm::vec3(w / 2, 0, w / 2), c + glm::vec3(w / 2, h, w / 2), 100.0f,
                             uniform({0.22f, 0.21f, 0.2f}, day), false);
            order[k] = {glm::length(c - eye), k};
        }
        std::sort(order.begin(), order.end(), std::greater<>());
        // The sun: a saturated white core (glow mask) in a pale halo (no mask).
        disc(sun, eye + 900.0f * toSun, -toSun, 900.0f * std::tan(4.0f * kPi / 180.0f),
             packColor({1.0f, 0.97f, 0.88f}, false));
        disc(sun, eye + 850.0f * toSun, -toSun, 850.0f * std::tan(1.8f * kPi / 180.0f), packColor({1, 1, 1}, true));
        // Painter's layers: ground (a flat colour to the horizon: a Clear), sky, sun, mountains,
        // stones.
        const DWORD groundColor = packColor(day.shade(glm::vec3(0.26f, 0.31f, 0.18f), eye, {0, 1, 0}), false);
        if (!clearSkyAndGround(groundColor, groundColor) || !drawSky(eye, {{-10.0f, {0.95f, 0.96f, 0.98f}},
                 {0.0f, {0.95f, 0.96f, 0.98f}},
                 {15.0f, {0.88f, 0.92f, 0.98f}},
                 {40.0f, {0.8f, 0.87f, 0.97f}},
                 {90.0f, {0.74f, 0.83f, 0.96f}}}) || !drawMesh(sun) || !drawMesh(mountains))
            return false;
        Mesh near;
        for (const auto& [distance, k] : order)
            near.vertices.insert(near.vertices.end(), stones[k].vertices.begin(), stones[k].vertices.end());
        return drawMesh(near);
    }
};

// The measuring scenes of skipping (docs/glare/scenes.md "sparse and dense"): a view panning over
// a wall of cells. `sparse`: the cells dark but never black (0.03–0.15, no glow mask) with
// small glowing squares over about 1 % of the pixels at full white; `dense`: every cell bright
// (0.85–1.0, glow mask on), above every technique's threshold.
class PanelScene final : public SceneBase {
public:
    explicit PanelScene(bool dense) : SceneBase(dense ? "dense" : "sparse"), m_dense(dense) {}

protected:
    D3DCOLOR clearColor() const override { return m_dense ? 0xFFD8D8D8u : 0x00080808u; }

    bool draw(int frame, int /*frameCount*/) override {
        const float w = float(width()), h = float(height());
        // The view pans by 3.3 pixels (at 1080p) a frame to the right and 1.1 down.
        const float pan = h / 1080.0f, ox = -3.3f * pan * float(frame), oy = -1.1f * pan * float(frame);
        const float cell = h / 18.0f;
        std::vector<ScreenVertex> v;
        auto quad = [&](float x0, float y0, float x1, float y1, DWORD c) {
            const ScreenVertex a{x0, y0, 0.5f, 1.0f, c}, b{x1, y0, 0.5f, 1.0f, c}, d{x1, y1, 0.5f, 1.0f, c},
                e{x0, y1, 0.5f, 1.0f, c};
            v.insert(v.end(), {a, b, d, a, d, e});
        };
        const int firstI = int(std::floor(-ox / cell)) - 1, firstJ = int(std::floor(-oy / cell)) - 1;
        for (int j = firstJ; float(j) * cell + oy < h; ++j)
            for (int i = firstI; float(i) * cell + ox < w; ++i) {
                const uint32_t id = uint32_t(i + 4096) * 8192u + uint32_t(j + 4096);
                const float base = m_dense ? 0.85f + 0.15f * noise(41, id) : 0.03f + 0.12f * noise(41, id);
                const glm::vec3 tint(1.0f - 0.1f * noise(42, id), 1.0f - 0.1f * noise(43, id), 1.0f - 0.1f * noise(44, id));
                quad(float(i) * cell + ox, float(j) * cell + oy, float(i + 1) * cell + ox, float(j + 1) * cell + oy,
                     packColor(base * (m_dense ? glm::vec3(1.0f) : tint), m_dense));
            }
        if (!m_dense) {
            // 36 squares of h/45 pixels: 36 / 45² · h / w of the frame, 1.0 % at 16:9. Each sits in
            // its own cell of a 9 × 4 grid of the view, so they never overlap.
            const float side = h / 45.0f;
            for (uint32_t k = 0; k < 36; ++k) {
                const float gx = w / 9.0f, gy = h / 4.0f;
                const float x = float(k % 9) * gx + (gx - side) * noise(45, k), y = float(k / 9) * gy + (gy - side) * noise(46, k);
                const float wobble = 0.5f * std::sin(0.37f * float(frame) + float(k));
                const glm::vec3 rgb = k % 3 == 0 ? glm::vec3(1.0f, 0.95f, 0.8f) : glm::vec3(1.0f);
                quad(x + wobble, y, x + wobble + side, y + side, packColor(rgb, true));
            }
        }
        return drawScreen(v);
    }

private:
    bool m_dense;
};

}  // namespace

const std::vector<SceneInfo>& sceneList() {
    static const std::vector<SceneInfo> list = {
        {"box", "three emissive objects in an open dark box; the camera backs out into daylight (eye adaptation)", 120},
        {"neon", "neon strips (glow mask) on a dark wall with bright non-glowing objects (glow)", 60},
        {"lights", "sparse point lights at night, some one pixel, moving by sub-pixel steps (stability, sprites)", 60},
        {"sky", "a bright sky with a saturated sun over darker ground (large bright areas)", 60},
        {"sparse", "a panning wall of dark cells (never black) with glowing squares over 1 % of the pixels (skipping)", 60},
        {"dense", "a panning wall of bright glowing cells, every pixel above every threshold (skipping)", 60},
    };
    return list;
}

std::unique_ptr<Scene> makeScene(std::string_view name, std::string& error) {
    if (name == "box") return std::make_unique<BoxScene>();
    if (name == "neon") return std::make_unique<NeonScene>();
    if (name == "lights") return std::make_unique<LightsScene>();
    if (name == "sky") return std::make_unique<SkyScene>();
    if (name == "sparse") return std::make_unique<PanelScene>(false);
    if (name == "dense") return std::make_unique<PanelScene>(true);
    std::string names;
    for (const SceneInfo& s : sceneList()) names += (names.empty() ? "" : ", ") + std::string(s.name);
    error = "unknown scene '" + std::string(name) + "' (scenes: " + names + ")";
    return nullptr;
}

}  // namespace glare
