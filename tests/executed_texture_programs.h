// Programs whose texture instructions are not all plain reads (ps11::TapPlan::executes): dependent
// reads (texbem, texbeml, texreg2ar/gb, texdp3tex, texm3x2 and texm3x3 rows, ps_1_4's dependent
// texld), coordinates as values (texcoord, texcrd), texkills of a register and the program's own
// depth (texdepth, texm3x2depth). Drawn by the executor's pre-sampled test
// (test_executor_fast.cpp) and the row-path tests (test_aligned_pass.cpp).
#pragma once

namespace executedprograms {

inline constexpr const char* kPrograms[] = {
    "ps_1_1\ntex t0\ntexbem t1, t0\nmad r0, t1, c0, v0_bias\n",
    "ps_1_1\ntex t0\ntexbeml t1, t0\nmul r0, t1, v0\n",
    "ps_1_1\ntex t0\ntex t1\ntexbem t2, t1\nmad r0, t2, c1, t0\n",
    "ps_1_3\ntex t0\ntexreg2ar t1, t0\ndp3_sat r0, t0_bx2, t1_bx2\n",
    "ps_1_2\ntex t0\ntexreg2gb t1, t0\nmul r0, t1, c2\n",
    "ps_1_1\ntex t0\ntexm3x2pad t1, t0_bx2\ntexm3x2tex t2, t0_bx2\nmul r0, t2, c0\n",
    "ps_1_1\ntex t0\ntexm3x3pad t1, t0_bx2\ntexm3x3pad t2, t0_bx2\ntexm3x3vspec t3, t0_bx2\nmad r0, t3, c0, t0\n",
    "ps_1_1\ntex t0\ntexm3x3pad t1, t0_bx2\ntexm3x3pad t2, t0_bx2\ntexm3x3tex t3, t0_bx2\nmul r0, t3, v0\n",
    "ps_1_2\ntex t0\ntexdp3tex t1, t0\nadd r0, t1, t0\n",
    "ps_1_1\ntexcoord t0\ntex t1\nmul r0, t0, t1\n",
    "ps_1_4\ntexld r0, t0\ntexcrd r1.rgb, t1\nmul r2, r0, c0\nphase\ntexld r3, r2\nmad_x2 r0.rgb, r3, r1, "
    "-r2\n+mov r0.a, r3.a\n",
    "ps_1_4\ntexcrd r0.rgb, t0\ntexld r1, t1\nphase\ntexld r2, r0\nmul r0.rgb, r2, r1\n+mov r0.a, r2.a\n",
    // Texkills of a register: a computed value's, and coordinates read as values.
    "ps_1_4\ntexld r1, t0\nsub r2.rgb, r1, c0\nphase\ntexkill r2\nmov r0.rgb, r1\n+mov r0.a, c1.a\n",
    "ps_1_4\ntexcrd r2.rgb, t1\ntexkill r2\ntexld r1, t0\nmul r0, r1, v0\n",
    // The program's own depth.
    "ps_1_4\ntexcrd r5.rgb, t1\nphase\ntexdepth r5\ntexld r0, t0\nmul r0, r0, v0\n",
    "ps_1_3\ntex t0\ntexm3x2pad t1, t0_bx2\ntexm3x2depth t2, t0_bx2\nmov r0, t0\n",
    // A stage or a coordinate set shared with a plain read: phase 2 reading stage 0 again,
    // coordinates read as values from a plain read's set (and a dependent read through them),
    // and a texkill of such a set.
    "ps_1_4\ntexld r0, t0\nphase\ntexld r0, r0\nmul r0, r0, c0\n",
    "ps_1_4\ntexld r1, t0\ntexcrd r2.rgb, t0\nmad r0.rgb, r1, r2, c1\n+mov r0.a, r1.a\n",
    "ps_1_4\ntexld r1, t0\ntexcrd r2.rgb, t0\nphase\ntexld r3, r2\nmad r0.rgb, r1, r3, c1\n+mov r0.a, r3.a\n",
    "ps_1_4\ntexkill t0\ntexcrd r2.rgb, t0\ntexld r1, t1\nmul r0.rgb, r1, r2\n+mov r0.a, r1.a\n",
};

}  // namespace executedprograms
