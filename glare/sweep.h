// The run-time-against-error sweep (`ps11 bench`, docs/bench.md): techniques × quality presets ×
// settings × hardware classes × renderers, each row timed over warm frames and its output measured
// against the technique's `ideal` reference and, where the technique approximates a stated piece
// of math, against that math (glare/intended.h); then the Pareto front of time against error.
// A library piece: the command line (tools/cmd_bench.cpp) and reports call it.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "emu/image_file.h"
#include "emu/renderer.h"
#include "glare/runner.h"
#include "glare/technique.h"
#include "ps11/hardware.h"

namespace glare {

// One hardware choice of a sweep: a class (ps11/hardware.h), or `ideal` (the default class under
// the ideal profile, the reference itself).
struct SweepHardware {
    std::string name;                               // "geforce4", …, "ideal"
    const ps11::HardwareClass* hardware = nullptr;  // null for `ideal` (the default class)
    bool ideal = false;
};
// Every class of ps11/hardware.h, then `ideal` (`--hardware all`).
std::vector<SweepHardware> allSweepHardware();
// A class by name, or `ideal`; nullopt for an unknown name.
std::optional<SweepHardware> findSweepHardware(std::string_view name);

// One setting swept over several values ("radius" over "4", "8"), values as --set takes them.
struct SweepSetting {
    std::string name;
    std::vector<std::string> values;
};

struct SweepSpec {
    std::vector<const Technique*> techniques;
    std::vector<std::string> qualities = {"published"};  // preset names (kPresetNames)
    // The cartesian product of these is applied over each preset, to every technique that has
    // the setting (a setting none of the techniques has is an error).
    std::vector<SweepSetting> settings;
    std::vector<SweepHardware> hardware;  // empty: the default class
    bool emu = true, gl = false;          // renderers
    bool glNative = true;                 // the GL renderer's mode (native: the speed peer)
    // Makes a device's GL renderer (runner/gl_backend.h glRendererFactory); needed when `gl`.
    std::function<std::unique_ptr<emu::Renderer>()> glRenderer;
    // The input: an image (`image`, named `imageName`), else the built-in scene `scene`, else each
    // technique's own scene (Technique::scene), drawn at width x height (frame 0 of its animation).
    std::optional<emu::FloatImage> image;
    std::string imageName, scene;
    uint32_t width = 1920, height = 1080;
    int frames = 20;  // timed frames per row, after one warm-up frame
    int threads = 0;  // the software renderer's worker threads (0: all cores)
};

struct SweepRow {
    std::string technique, quality;
    Settings settings;
    std::vector<std::pair<std::string, std::string>> swept;  // the --set values of this row, as text
    std::string hardware, precision;  // SweepHardware::name, the profile that ran
    std::string backend;              // "emu", "gl"
    std::string glMode;               // "native" or "exact" on gl, "" on emu
    std::string scene;                // the scene's name or the image's
    uint32_t width = 0, height = 0;
    int frames = 0;
    double msMedian = 0, msMin = 0, msMax = 0;  // the technique's passes per timed frame
    ImageError error;                           // the 8-bit output against the ideal reference's
    std::optional<ImageError> intendedError;    // against the intended math's (glare/intended.h), where there is one
    bool pareto = false;
};

// Progress lines ("[3/12] glow published geforce4 emu: 28.1 ms") for stderr.
using SweepProgress = std::function<void(const std::string&)>;

// Runs the sweep. Rows come in order technique, quality, settings, hardware, backend. The rows of
// one (technique, quality, settings) run their frames interleaved (frame f on every renderer, then
// f + 1), so machine load drifts alike for the rows a front compares. Timed frames run every pass
// (RunnerOptions::skip off: a still input would otherwise be reused and time nothing); the ideal
// reference runs with reuse on (the same bytes, docs/glare/README.md "Reuse") once per
// (technique, settings, input) and is shared by the rows. Every row runs warm-up + frames frames
// of one sequence and is measured on its last. False with `error` on the first failure.
bool runSweep(const SweepSpec& spec, std::vector<SweepRow>& rows, std::string& error,
              const SweepProgress& progress = {});

// Sets SweepRow::pareto: per (technique, scene, size), a row is on the front when no other row is
// both faster (msMedian) and more accurate (error.mean, ties broken by error.max).
void markPareto(std::vector<SweepRow>& rows);
// `a` beats `b` on both counts (strictly faster and strictly more accurate), same group or not.
bool dominates(const SweepRow& a, const SweepRow& b);

}  // namespace glare
