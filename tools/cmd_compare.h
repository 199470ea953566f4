// `ps11 compare`: the emulator against the GL renderer (docs/gl-backend.md "Cross-check").
//   ps11 compare SHADER.psh|FILE.ps11test [--size WxH] [--seed S] [--hardware H] [--precision P]
//                [--heatmap OUT.png] [--json] [--gl osmesa|egl] [--gl-filtering]
//   ps11 compare --random N [--seed S] [--minor 1..4] [--out DIR] [--json] [--gl osmesa|egl]
// A test file's draws, or a bare shader drawn over random textures and interpolants, run on
// both renderers; per draw: pixels, exact pixels, pixels more than one level apart, max |Δ|.
// --gl-filtering lets GL's texture unit filter in the float profiles (an experiment on a GPU's
// filtering, no longer a bit-exact renderer). --random draws N random valid programs; a mismatch is shrunk to a minimal
// program and written as a .ps11test regression case. Exit 0 when everything agrees within the cross-check's target
// (fixed-point profiles: no pixel more than one level apart; float targets: |Δ| <= 1e-4), 1 when
// not or on a user error, 2 on a usage error.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

int cmdCompare(const std::vector<std::string>& args);

}  // namespace ps11
