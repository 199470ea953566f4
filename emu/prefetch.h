// How far ahead the row paths ask for memory they are about to read (docs/device.md "Aligned
// passes"). A 1080p pass streams its texel rows and its target from memory; one thread alone
// waits on each line it touches unless the line was asked for before. Measured on the glare
// frames (alternated, medians): the 4:1 reductions −35 %, the screen composite −10 %, the float
// composites −6 %; asking for short rows (a 480×270 blur's, a sprite image's) cost more than it
// saved, hence the thresholds.
#pragma once

#include <cstddef>

namespace emu {

// Kernels reading a texel row ask for the line this many bytes ahead of the one they read (the
// fx8 row path's deinterleave and 4:1 pair sums: past a row's end, the next texel row, which
// such passes read next), and the stores of ONE/ONE sums the target's line this far ahead of
// the one they read (the fx8 row path's store kernels — lanes, `verticalStore`, the copied and
// filled words — and the RowSource row they add to: the 1080p composites −7 to −16 %; the float
// merger's sum into 8-bit targets: −2 to −6 %)…
constexpr int kPrefetchAhead = 2048;
// …and the float row path's decoding of a texel row where the row spans at least this many bytes
// (its H rows are built per texel row; a minified sprite image's short rows are read scattered).
constexpr int kPrefetchRowBytes = 4096;

}  // namespace emu
