// The ps_1_1 passes the benchmarks share (bench_executor, bench_draw, bench_emu_vs_gl), written once.
#pragma once

namespace bench {

// The 4-tap blur pass of bloom/glare techniques: four bilinear taps weighted by c0.
constexpr const char* kBlur4 =
    "ps_1_1\n"
    "tex t0\n"
    "tex t1\n"
    "tex t2\n"
    "tex t3\n"
    "mul r0, t0, c0\n"
    "mad r0, t1, c0, r0\n"
    "mad r0, t2, c0, r0\n"
    "mad r0, t3, c0, r0\n";

// A 1:1 (or reducing) copy: one tap.
constexpr const char* kCopy =
    "ps_1_1\n"
    "tex t0\n"
    "mov r0, t0\n";

}  // namespace bench
