// The numerical-stability suite (`ps11 stress`, docs/stress.md): GLARE.md §7's 8-bit pitfalls run
// on the emulated 1.1-class card beside their predictions and fixes, §6's quality metrics per
// technique, and robustness against NaN, Inf, huge HDR values and long adaptation. A library so
// the command line, the tests and a report print the same numbers.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "glare/runner.h"

namespace glare {

// A number (one entry with an empty name) or an object of named numbers. NaN: not measured.
using StressValue = std::vector<std::pair<std::string, double>>;
inline StressValue stressNumber(double v) { return {{"", v}}; }
// The entry `key` of v (for a single number, key ""), or NaN.
double stressGet(const StressValue& v, const std::string& key = "");

// One pitfall of GLARE.md §7: the prediction from its formula (plain double arithmetic), the
// measurement (the real ps_1_1 passes on the emulated card), a fix that still fits ps_1_1 and
// its measured effect. `fix` starts with "none" where the project has no fix; then
// measuredWithFix is empty.
struct StressItem {
    std::string name;      // "smoothing_dead_band"
    std::string unit;      // what the numbers count ("levels short of the target")
    std::string setup;     // what ran: technique, settings, image size
    StressValue predicted, measured;
    std::string fix;
    StressValue measuredWithFix;
    std::string note;      // where the measurement and the prediction part, and why
    // What a picture of the pitfall plots (a report draws them): named curves over frames, or
    // the cells of a grid, row by row; `seriesUnit` says what the values are.
    std::vector<std::pair<std::string, std::vector<double>>> series;
    std::string seriesUnit;
};

struct StressOptions {
    const ps11::HardwareClass* hardware = nullptr;  // null: the default 1.1-class card
    uint32_t size = 256;                            // the side of the §6 metric images (and the blur's scene)
    int adaptationFrames = 10000;                   // the long adaptation run of the robustness checks
};

// The options of a Runner on the suite's card, w x h, skipping off (every pass runs).
RunnerOptions stressRunnerOptions(const StressOptions& o, uint32_t w, uint32_t h);

// GLARE.md §7, one function per item (each makes its own runners; false with `error` when a run
// fails, which is a bug, not a finding).
bool stressSmoothingDeadBand(const StressOptions& o, StressItem& item, std::string& error);
bool stressBlurEnergyDrift(const StressOptions& o, StressItem& item, std::string& error);
bool stressWeightSumRounded(const StressOptions& o, StressItem& item, std::string& error);
bool stressWeightSumDiffused(const StressOptions& o, StressItem& item, std::string& error);
bool stressFeedbackResidue(const StressOptions& o, StressItem& item, std::string& error);
bool stressDecimationCapture(const StressOptions& o, StressItem& item, std::string& error);

// The prediction of Sousa's pinwheel blur (blur_passes passes of 4 bilinear taps, weight 0.25 on
// the 8-bit grid) of one texel of level 255 in a side x side target, computed in double with
// the card's rules: 8-bit sub-texel weights, each tap and each instruction rounded (to nearest,
// ties to even) or truncated. Returns energy after / before.
double predictPinwheelEnergy(int passes, bool truncate, int side = 32);
// The 8-bit smoothing recurrence of the adapted amount (GLARE.md §1, §7), in levels: the card holds
// a as a8 = round(255a); each frame A ← round_half_even((a8·L + (255 − a8)·A)/255). The levels after
// each of `frames` frames from `start`.
std::vector<int> predictSmoothingLevels(double a, int target, int start, int frames);
// The glow's feedback loop once its source is black (GLARE.md §7), in levels: y ← B_v(B_h(Q(k8·y/255)))
// where a 1D pass B of a uniform level Y is the weighted4.psh chain r ← round(Y·n_i/255 + r) over
// each 4 error-diffused weights n_i, the passes after the first added exactly (ONE, ONE). The
// levels after each of `frames` frames from y0.
std::vector<int> predictFeedbackLevels(const Settings& glowSettings, int y0, int frames);
// The kernels the weight-sum items run: the pyramid's 5/16, 6/16, 5/16 and the glow's published 1D kernel.
std::vector<std::pair<std::string, std::vector<double>>> stressKernels();

// The pixel (cx, cy) of an 8x8 cell that the adaptive bright pass's point sample reads.
bool stressCapturedOffset(const StressOptions& o, uint32_t& cx, uint32_t& cy, std::string& error);

// The adapted amount A (level of the 1x1 target) after each of `frames` frames of the adaptive
// technique with `settings` on `image` (a fresh runner; frame 0 starts as settings say).
bool adaptationLevels(const StressOptions& o, const Settings& settings, const std::vector<emu::FloatImage>& images,
                      const std::vector<int>& imageOfFrame, std::vector<int>& levels, std::string& error);

// GLARE.md §6 per technique (published settings, size x size).
struct TechniqueMetrics {
    std::string technique;
    uint32_t size = 0;
    int stabilityFrames = 0;        // 1/8-pixel steps through one period of the coarsest grid
    double stabilityEnergy = 0;     // (max − min)/mean of total glare energy over those frames
    double stabilityPeak = 0;       // the same of the peak glare value
    double fireflyShare = 0;        // share of the glare energy from one pixel 1000x the mean
    int fireflyArea = 0;            // pixels whose glare that pixel changes by a level or more
    double dcGain = 0;              // glare / input of a uniform 0.25 image (threshold 0, sprites: theirs)
    double impulseGain = 0;         // summed glare / input of one white pixel (threshold as for dcGain)
    double r50 = 0, r90 = 0;        // radii (pixels) holding 50 % and 90 % of the impulse's glare
    double visibilityRadius = 0;    // farthest pixel the impulse's glare reaches by a level or more
    double anisotropy = 0;          // max/min r90 over 8 angular sectors (NaN: no glare)
    int bandLevels = 0;             // distinct levels along the impulse's glare, centre outwards along +x
    int bandStep = 0;               // largest step between neighbours there (levels)
};
bool stressMetrics(const StressOptions& o, const Technique& t, TechniqueMetrics& m, std::string& error);

// Robustness: a check that passes or fails, with what it saw.
struct RobustnessCheck {
    std::string name;
    bool pass = false;
    std::string detail;
};
bool stressRobustness(const StressOptions& o, std::vector<RobustnessCheck>& checks, std::string& error);
// 10 000 frames of adaptation (alternating images): every level in range and every phase ending
// within the dead band of its target.
bool stressLongAdaptation(const StressOptions& o, int frames, RobustnessCheck& check, std::string& error);

struct StressReport {
    std::string hardware;  // the card's name
    std::vector<StressItem> items;
    std::vector<TechniqueMetrics> metrics;
    std::vector<RobustnessCheck> robustness;
    bool robust() const;
};
bool runStress(const StressOptions& o, StressReport& report, std::string& error);

}  // namespace glare
