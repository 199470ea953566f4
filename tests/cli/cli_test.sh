#!/usr/bin/env bash
# End-to-end checks of the ps11 command line: outputs, exit codes (0 ok, 1 user error,
# 2 usage) and that user errors name the file and place. Usage: cli_test.sh PATH/TO/ps11
set -u
ps11="$1"
root="$(cd "$(dirname "$0")/../.." && pwd)"  # the project (the corpus under tests/shaders)
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
expect_rc() { # expected-rc description command...
    local want="$1" what="$2"; shift 2
    "$@" >"$work/out" 2>"$work/err"
    local rc=$?
    [ "$rc" = "$want" ] || fail "$what: exit $rc, expected $want; stderr: $(head -c 400 "$work/err")"
}
expect_in() { # file text description
    grep -qF -- "$2" "$1" || fail "$3: '$2' not in $(basename "$1"): $(head -c 400 "$1")"
}
expect_json() { # file description: the file is one JSON document
    python3 -c 'import json, sys; json.load(open(sys.argv[1], encoding="utf-8"))' "$1" 2>/dev/null ||
        fail "$2: not JSON: $(head -c 400 "$1")"
}

printf 'ps_1_1\ntex t0\nadd r0.rgb, t0, v0\n+mov r0.a, t0\n' >"$work/a.psh"
expect_rc 0 "asm --hex" "$ps11" asm "$work/a.psh" --hex
expect_in "$work/out" "0xffff0101 0x00000042 0xb00f0000 0x00000002" "asm --hex words"
expect_rc 0 "asm -o" "$ps11" asm "$work/a.psh" -o "$work/a.bin"
[ "$(stat -c %s "$work/a.bin")" = 44 ] || fail "asm -o wrote $(stat -c %s "$work/a.bin") bytes, expected 44"
expect_rc 0 "disasm binary" "$ps11" disasm "$work/a.bin"
expect_in "$work/out" "+mov r0.a, t0" "disasm text"
cp "$work/out" "$work/b.psh"
expect_rc 0 "re-assemble disassembly" "$ps11" asm "$work/b.psh" -o "$work/b.bin"
cmp -s "$work/a.bin" "$work/b.bin" || fail "round trip through the CLI changed the tokens"
"$ps11" asm "$work/a.psh" --hex >"$work/a.hex" 2>/dev/null
expect_rc 0 "disasm hex words (detected)" "$ps11" disasm "$work/a.hex"
expect_rc 0 "asm from stdin" "$ps11" asm - --hex <"$work/a.psh"
expect_rc 0 "check" "$ps11" check "$work/a.psh" "$work/a.bin"
expect_in "$work/out" "arithmetic slots: 1/8" "check statistics"
expect_rc 0 "check --json" "$ps11" check --json "$work/a.psh"
expect_in "$work/out" '"arithSlots": 1' "check --json"
# Names JSON must escape (quote, backslash, newline, tab, a control byte, a byte that is not UTF-8),
# and an unreadable first file: still one valid JSON array, each name read back as written.
odd="$work/q\"uo\\te
tab	ctl$(printf '\001')lat$(printf '\351').psh"
cp "$work/a.psh" "$odd"
expect_rc 1 "check --json odd names" "$ps11" check --json "$work/missing.psh" "$odd" "$work/a.psh"
python3 - "$work/out" "$odd" "$work/a.psh" <<'PY' || fail "check --json with odd names: $(head -c 400 "$work/out")"
import json, os, sys
j = json.load(open(sys.argv[1], encoding="utf-8"))
odd = os.fsencode(sys.argv[2]).decode("utf-8", "replace")  # a byte that is not UTF-8 becomes U+FFFD
assert [f["file"] for f in j] == [odd, sys.argv[3]], [f["file"] for f in j]
assert all(f["valid"] and f["stats"]["arithSlots"] == 1 for f in j)
PY
printf 'ps_1_1\n#ifdef TWO\nmov r0, v1\n#else\nmov r0, v0\n#endif\n' >"$work/d.psh"
expect_rc 0 "asm -D" "$ps11" asm "$work/d.psh" -D TWO --hex
expect_in "$work/out" "0x90e40001" "-D selects the #ifdef branch"
mkdir -p "$work/inc" && printf '#define SRC v1\n' >"$work/inc/defs.h"
printf '#include "defs.h"\nps_1_1\nmov r0, SRC\n' >"$work/i.psh"
expect_rc 1 "include not found without -I" "$ps11" asm "$work/i.psh"
expect_in "$work/err" "i.psh:1:" "include error names the file and line"
expect_rc 0 "asm -I" "$ps11" asm "$work/i.psh" -I "$work/inc" --hex
expect_in "$work/out" "0x90e40001" "-I finds the include"

# User errors: exit 1, file:line:col and code.
printf 'ps_1_1\nmov r0, v0\nmov r1, r1\ndp4 r0, v0, v1\n' >"$work/bad.psh"
expect_rc 1 "check invalid" "$ps11" check "$work/bad.psh"
expect_in "$work/err" "bad.psh:3:9: error P2090" "read-before-write diagnostic"
expect_in "$work/err" "bad.psh:4:1: error P2002" "dp4 in ps_1_1 diagnostic"
expect_rc 1 "asm invalid" "$ps11" asm "$work/bad.psh"
expect_rc 0 "asm --no-validate" "$ps11" asm "$work/bad.psh" --no-validate
expect_rc 1 "missing file" "$ps11" asm "$work/none.psh"
expect_in "$work/err" "none.psh" "missing file named"
expect_rc 1 "disasm text" "$ps11" disasm "$work/a.psh"
expect_in "$work/err" "P3019" "disasm on text explains"
head -c 10 "$work/a.bin" >"$work/trunc.bin"
expect_rc 1 "disasm truncated" "$ps11" disasm "$work/trunc.bin"
expect_in "$work/err" "P3001" "odd-size binary"
expect_rc 1 "write into a missing folder" "$ps11" asm "$work/a.psh" -o "$work/no/such/dir.bin"

# Registers the version does not have are the assembler's error (P1114), with validation off
# too, as Microsoft's assembler does (Wine's d3dcompiler tests/asm.c failure_test).
printf 'ps_1_3\nmov r5, r0\n' >"$work/r5.psh"
expect_rc 1 "asm --no-validate refuses r5 in ps_1_3" "$ps11" asm "$work/r5.psh" --no-validate
expect_in "$work/err" "r5.psh:2:5: error P1114: register 'r5' does not exist in ps_1_3 (r0-r1)" "P1114 names file:line:col"
printf 'ps_1_3\ntex t5\n' >"$work/t5.psh"
expect_rc 1 "asm --no-validate refuses t5 in ps_1_3" "$ps11" asm "$work/t5.psh" --no-validate
expect_in "$work/err" "t5.psh:2:5: error P1114: register 't5'" "P1114 for tex t5"
printf 'ps_1_4\nmov r5, r0\n' >"$work/r5ok.psh"
expect_rc 0 "asm --no-validate takes r5 in ps_1_4" "$ps11" asm "$work/r5ok.psh" --no-validate
# The same register in a token stream reaches the validator: still an error (P2030).
printf '0xffff0103 0x00000001 0x800f0005 0x80e40000 0x0000ffff\n' >"$work/r5.hex"
expect_rc 1 "check tokens with r5 in ps_1_3" "$ps11" check "$work/r5.hex"
expect_in "$work/err" "error P2030: r5 is out of range: ps_1_3 has r0-r1" "P2030 on decoded tokens"

# Mistyped names get a suggestion; quoted source is cut to a readable length.
printf 'ps_1_1\nmull r0, v0, v1\n' >"$work/mull.psh"
expect_rc 1 "unknown instruction" "$ps11" asm "$work/mull.psh" --no-validate
expect_in "$work/err" "mull.psh:2:1: error P1103: unknown instruction 'mull'; did you mean 'mul'?" "instruction suggestion"
{ printf 'ps_1_1 '; head -c 1048576 /dev/zero | tr '\0' 'x'; printf '\nmov r0, v0\n'; } >"$work/long.psh"
expect_rc 1 "a 1 MB line" "$ps11" asm "$work/long.psh"
expect_in "$work/err" "long.psh:1:8: error P1111: unexpected text after the version: 'xxx" "long line names line:col"
[ "$(wc -c <"$work/err")" -lt 300 ] || fail "a 1 MB line gave $(wc -c <"$work/err") bytes of diagnostics"

# check --ranges: Sousa's mov_x4 then mul clamps from t0 > 0.25 (ps11/range_proof.h).
printf 'ps_1_1\ntex t0\nmov_x4 r1, t0\nmul r0, r1, t0\n' >"$work/sq.psh"
expect_rc 0 "check --ranges" "$ps11" check --ranges "$work/sq.psh"
expect_in "$work/out" "CLAMPS .rgba at ±1; from t0 > 0.251" "check --ranges onset"
expect_in "$work/out" "not range-safe: line 3 (mov_x4 r1, t0) clamps" "check --ranges verdict"
expect_rc 0 "check --ranges restricted" "$ps11" check --ranges "$work/sq.psh" --tex0-range 0,0.2
expect_in "$work/out" "range-safe: no register clamp acts" "check --ranges with t0 in [0, 0.2]"
expect_rc 0 "check --ranges --json" "$ps11" check --ranges --json "$work/sq.psh" --tex0-point
python3 - "$work/out" <<'PY' || fail "check --ranges --json: fields"
import json, sys
j = json.load(open(sys.argv[1]))
i = j["instructions"]
assert [x["line"] for x in i] == [2, 3, 4], i
assert i[1]["clamps"] and not i[0]["clamps"] and not i[2]["clamps"]
assert i[1]["dst"] == "r1" and i[1]["min"] == [0, 0, 0, 0] and i[1]["max"] == [1, 1, 1, 1]
assert i[1]["clamp_onsets"][0]["input"] == "t0" and 0.24 < i[1]["clamp_onsets"][0]["above"] < 0.252
b = j["outputs"]["r0"]["bound_levels"]
assert 0 < b["fx12"] < b["fx8"] < 10, b
assert j["range_safe"] is False
PY
expect_rc 2 "check --ranges bad range" "$ps11" check --ranges "$work/sq.psh" --tex0-range 1,0
expect_in "$work/err" "--tex0-range" "bad range names the option"
expect_rc 2 "range option without --ranges" "$ps11" check "$work/sq.psh" --tex0-range 0,1
# debug: one pixel, the class beside ideal; mov_x4 of 0.627 clamps on the 1.1-class card.
expect_rc 0 "debug" "$ps11" debug "$work/sq.psh" --tex0 0xffa0a0a0
expect_in "$work/out" ">> 3" "debug marks the first divergence"
expect_in "$work/out" "clamp" "debug names the clamp"
expect_rc 0 "debug --json" "$ps11" debug "$work/sq.psh" --tex0 0xff202020 --json
python3 - "$work/out" <<'PY' || fail "debug --json: fields"
import json, sys
j = json.load(open(sys.argv[1]))
s = j["steps"]
assert [x["line"] for x in s] == [2, 3, 4], s
assert s[0]["grid"] == [32, 32, 32, 255] and s[0]["emulated"] == s[0]["ideal"]
assert j["first_divergence"] is None or j["first_divergence"] in (3, 4)
assert all(isinstance(x["why"], list) for x in s)
PY
expect_rc 2 "debug without a shader" "$ps11" debug
expect_rc 1 "debug of a missing file" "$ps11" debug "$work/missing.psh"
# debug --technique: one output pixel of a glare frame followed back through its passes.
expect_rc 0 "debug --technique" "$ps11" debug --technique adaptive --scene box --size 160x90 --pixel 80,45
expect_in "$work/out" "composite (shader composite_screen.psh), pixel (80, 45)" "debug --technique traces the composite"
expect_in "$work/out" "most error added by pass" "debug --technique names the pass that added the most error"
expect_rc 0 "debug --technique --json" "$ps11" debug --technique adaptive --scene box --size 160x90 --pixel 80,45 --json
python3 - "$work/out" <<'PY' || fail "debug --technique --json: fields"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["technique"] == "adaptive" and j["pixel"] == [80, 45] and j["frame"] == 0
p = j["passes"]
assert len(p) > 5 and p[-1]["pass"] == "composite" and p[-1]["pixel"] == [80, 45]
names = [x["pass"] for x in p]
assert j["most_error"]["pass"] in names, j["most_error"]
for x in p:
    assert {"pass", "shader", "pixel", "target", "steps", "first_divergence", "output"} <= set(x), x.keys()
    assert set(x["output"]) == {"emulated", "ideal", "levels"}
    if x["kind"] == "shader":
        assert x["steps"] and all({"line", "text", "emulated", "ideal", "why"} <= set(s) for s in x["steps"])
        assert x["traced"]["emulated"] == x["output"]["emulated"], x["pass"]
assert any(s["origin"] == "scene input" for x in p for s in x["sources"])
PY
expect_rc 2 "debug --technique: pixel outside the frame" "$ps11" debug --technique adaptive --scene box --size 160x90 --pixel 160,0
expect_in "$work/err" "--pixel 160,0" "the outside pixel names --pixel"
expect_rc 2 "debug --technique: bad --pixel" "$ps11" debug --technique adaptive --scene box --pixel 3
expect_rc 2 "debug --technique: unknown technique" "$ps11" debug --technique nope --scene box --pixel 1,1
expect_rc 2 "debug --technique: unknown scene" "$ps11" debug --technique adaptive --scene nope --pixel 1,1
expect_rc 1 "debug --technique: missing image" "$ps11" debug --technique adaptive --in "$work/missing.png" --pixel 1,1
# eval: one pixel on the executor.
printf 'ps_1_1\nmov r0, v0\n' >"$work/e.psh"
expect_rc 0 "eval" "$ps11" eval "$work/e.psh" v0=0.5,0.25,1
expect_in "$work/out" "r0     0.501961 0.25098 1 0" "eval r0 floats (fx8, missing component 0)"
expect_in "$work/out" "grid   128 64 255 0" "eval grid integers"
expect_rc 0 "eval --precision float" "$ps11" eval "$work/e.psh" v0=0.5,0.25,1,1 --precision float
expect_in "$work/out" "r0     0.5 0.25 1 1" "eval float profile"
printf 'ps_1_1\ntex t0\nmul r0, t0, c0\n' >"$work/et.psh"
expect_rc 0 "eval --tex0" "$ps11" eval "$work/et.psh" --tex0 0xff808080 c0=1,1,1,1 t0=0.5,0.5
expect_in "$work/out" "grid   128 128 128 255" "eval samples the 1x1 texture"
printf 'ps_1_1\ntexkill t0\nmov r0, v0\n' >"$work/ek.psh"
expect_rc 0 "eval texkill" "$ps11" eval "$work/ek.psh" t0=-1
expect_in "$work/out" "killed" "eval reports killed"
# Hardware classes: eval names the class; signed texels decode by the class's rule.
printf 'ps_1_1\ndef c0, 0.5, 0.5, 0.5, 0.5\ntex t0\nmad r0, t0, c0, c0\n' >"$work/sf.psh"
expect_rc 0 "eval default class" "$ps11" eval "$work/sf.psh" --tex0 L6V5U5:0x0011 t0=0.5,0.5
expect_in "$work/out" "ps_1_1, hardware geforce4 (1.1-class), fx8, max value 1" "eval names the default class"
expect_in "$work/out" "r0     0 0.501961 0.501961 1" "geforce4: L6V5U5 -15 reads -1 (snorm)"
expect_rc 0 "eval --hardware d3d9" "$ps11" eval "$work/sf.psh" --tex0 L6V5U5:0x0011 --hardware d3d9 t0=0.5,0.5
expect_in "$work/out" "hardware d3d9 (D3D9-class), float, max value 65504" "eval names the chosen class"
expect_in "$work/out" "r0     0.03125 0.5 0.5 1" "d3d9: L6V5U5 -15 reads -15/16 (asymmetric)"
expect_rc 0 "eval --hardware geforce7" "$ps11" eval "$work/sf.psh" --tex0 L6V5U5:0x0011 --hardware geforce7 t0=0.5,0.5
expect_in "$work/out" "r0     0.0433071 0.5 0.5 1" "geforce7: L6V5U5 -15 widened to 0x8c"
expect_rc 0 "eval --hardware with --precision" "$ps11" eval "$work/sf.psh" --hardware d3d9 --precision fx8
expect_in "$work/out" "hardware d3d9 (D3D9-class), fx8 (override), max value 65504" "an override is marked"
printf 'ps_1_4\nmov r0, c0\n' >"$work/p14.psh"
expect_rc 0 "eval ps_1_4 default class" "$ps11" eval "$work/p14.psh"
expect_in "$work/out" "hardware radeon8500 (1.4-class), fx12, max value 8" "ps_1_4 runs on the 1.4-class card by default"
expect_rc 1 "eval beyond the class's version" "$ps11" eval "$work/p14.psh" --hardware geforce3
expect_in "$work/err" "hardware geforce3 runs ps_1_1 ... ps_1_1" "the class's version limit is named"
expect_rc 2 "eval unknown class" "$ps11" eval "$work/e.psh" --hardware d3d99
expect_in "$work/err" "unknown hardware class 'd3d99'" "unknown class named"
expect_in "$work/err" "did you mean 'd3d9'?" "nearest class suggested"
expect_rc 1 "eval texel word too wide" "$ps11" eval "$work/sf.psh" --tex0 V8U8:0x10000
expect_in "$work/err" "hex word of 16 bits" "the format's width named"
expect_rc 1 "eval unknown texel format" "$ps11" eval "$work/sf.psh" --tex0 R5G6B5:0x1
expect_in "$work/err" "bad format in --tex0: 'R5G6B5'" "bad format named"
expect_rc 0 "hardware" "$ps11" hardware
expect_in "$work/out" "geforce4    1.1-class  ps_1_3" "hardware lists the default class"
expect_in "$work/out" "(default for ps_1_4)" "hardware marks the ps_1_4 default"
expect_rc 0 "hardware --json" "$ps11" hardware --json
expect_json "$work/out" "hardware --json"
expect_in "$work/out" '"name": "geforce7", "kind": "D3D9-class"' "hardware --json"
expect_in "$work/out" '"coissued_cnd": "sequential"' "hardware --json behaviours"
expect_rc 2 "hardware bad option" "$ps11" hardware --bogus
expect_rc 1 "eval bad value" "$ps11" eval "$work/e.psh" t0=x
expect_in "$work/err" "ps11: eval: bad value for t0: 'x'" "eval names the bad argument"
expect_rc 1 "eval too many components" "$ps11" eval "$work/e.psh" v0=1,2,3,4,5
expect_rc 1 "eval bad texture colour" "$ps11" eval "$work/e.psh" --tex0 red
expect_in "$work/err" "--tex0" "eval names the bad texture option"
expect_rc 1 "eval invalid shader" "$ps11" eval "$work/bad.psh"
expect_in "$work/err" "bad.psh:3:9: error P2090" "eval shows the shader diagnostics"
expect_rc 2 "eval without shader" "$ps11" eval
expect_rc 2 "eval unknown register" "$ps11" eval "$work/e.psh" q0=1
expect_rc 2 "eval unknown option" "$ps11" eval "$work/e.psh" --bogus

# test: evals run on the executor; failures name the probe's line.
printf '[pixel shader]\nps_1_1\nmov r0, v0\n[test]\neval\n  v0 1 0 0 1\nprobe eval rgba 1 0 0 1 tol 0\nprobe eval rgb 0 1 0 tol 0.01\ntodo(fx12) probe eval rgb 1 0 0\ntodo probe eval rgb 0 0 1\n' >"$work/t.ps11test"
expect_rc 1 "test with a failing eval probe" "$ps11" test "$work/t.ps11test"
expect_in "$work/out" "t.ps11test:8: probe failed: expected rgb 0 1 0 tol 0.01, got 1 0 0 = [255 0 0]/255 (hardware geforce4 (1.1-class), fx8, max value 1)" "probe failure names file, line, values and the hardware class"
expect_in "$work/out" "probes: 2 passed, 1 failed, 1 todo" "probe counts"
expect_rc 1 "a todo probe that passes is an error" "$ps11" test "$work/t.ps11test" --precision fx12
expect_in "$work/out" "t.ps11test:9: error: todo probe passed" "passing todo reported"
sed -i '8d' "$work/t.ps11test"
expect_rc 0 "test with passing eval probes" "$ps11" test "$work/t.ps11test" --stats
expect_in "$work/out" "1 file: 1 passed, 0 failed, 0 not yet runnable; probes: 2 passed, 0 failed, 1 todo" "summary"
expect_in "$work/out" "1 pixels, 1 instructions executed" "--stats"
# ps11 bench: a tiny sweep (2 values x 2 hardware x emu), its JSON, the ideal row's zero error and
# the Pareto front's definition; bad arguments name themselves and exit 2.
expect_rc 0 "bench --json" "$ps11" bench --technique adaptive --set blur_passes=2,5 --hardware geforce4,ideal --size 160x90 --frames 2 --backend emu --json
expect_in "$work/err" "ps11 bench: [4/4] adaptive" "bench progress on stderr"
if command -v python3 >/dev/null; then
    python3 - "$work/out" <<'PY' || fail "bench --json: rows, fields, ideal error or Pareto front wrong"
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
assert len(rows) == 4, len(rows)
for r in rows:
    for k in ("technique", "quality", "settings", "hardware", "precision", "backend", "scene", "size",
              "ms_median", "ms_min", "ms_max", "error", "pareto"):
        assert k in r, k
    for k in ("max_levels", "mean_levels", "differing_pct", "psnr"):
        assert k in r["error"], k
    if r["hardware"] == "ideal":
        assert r["error"]["max_levels"] == 0 and r["error"]["mean_levels"] == 0 and r["error"]["psnr"] is None, r
def acc(r): return (r["error"]["mean_levels"], r["error"]["max_levels"])
def beats(a, b): return a["ms_median"] < b["ms_median"] and acc(a) < acc(b)
for b in rows:
    dominated = [a for a in rows if a is not b and beats(a, b)]
    assert b["pareto"] == (not dominated), b
    assert b["pareto"] or any(a["pareto"] for a in dominated), b
assert sorted(r["settings"]["blur_passes"] for r in rows) == [2, 2, 5, 5]
PY
fi
expect_rc 0 "bench text" "$ps11" bench --technique pyramid --scene box --size 96x64 --frames 1 --backend emu
expect_in "$work/out" "Pareto front" "bench prints the front"
expect_in "$work/out" "pyramid on box 96x64:" "bench names the front's technique"
expect_rc 2 "bench unknown technique" "$ps11" bench --technique glwo
expect_in "$work/err" "unknown technique 'glwo' (techniques: adaptive, glow" "bench lists the techniques"
expect_rc 2 "bench unknown setting" "$ps11" bench --technique quarter --set radius=1,2
expect_in "$work/err" "--set radius=1,2: no setting 'radius' in quarter" "bench names the setting"
expect_rc 2 "bench bad setting value" "$ps11" bench --technique glow --set radius=4,x
expect_in "$work/err" "--set radius=4,x:" "bench names the bad value's --set"
expect_rc 2 "bench bad hardware" "$ps11" bench --hardware geforce9
expect_in "$work/err" "--hardware: unknown hardware class" "bench names the hardware argument"
expect_rc 2 "bench bad frames" "$ps11" bench --frames 0
expect_in "$work/err" "--frames takes a count" "bench says what --frames takes"
expect_rc 2 "bench bad backend" "$ps11" bench --backend vulkan
expect_in "$work/err" "--backend takes emu, gl or both, not 'vulkan'" "bench lists the backends"
expect_rc 2 "bench scene and image" "$ps11" bench --scene box --in "$work/tex.png"
expect_rc 1 "bench missing image" "$ps11" bench --in "$work/none.png" --backend emu
expect_in "$work/err" "none.png" "bench names the missing image"

if ! grep -q "PS11_GL=OFF" <("$ps11" info 2>&1); then
    expect_rc 0 "evals run on gl as one-pixel draws" "$ps11" test "$work/t.ps11test" --backend gl
    expect_in "$work/out" "1 file: 1 passed, 0 failed, 0 not yet runnable; probes: 2 passed, 0 failed, 1 todo" "gl evals"
fi

# test: draws run on the device; a pixel probe failure names the line, the expected colour and
# the first pixel that differs; a draw the device refuses fails with the device's message.
printf '[render target]\nsize 4 2\nclear 0xff000000\n[pixel shader]\nps_1_1\nmov r0, v0\n[test]\ndraw quad diffuse 0xff0000ff rect 0 0 2 2\nprobe rect 0 0 2 2 rgba 0xff0000ff\nprobe 3 1 rgba 0xff000000\nprobe all rgb 0x0000ff\n' >"$work/d.ps11test"
expect_rc 1 "draw with a failing pixel probe" "$ps11" test "$work/d.ps11test" --stats
expect_in "$work/out" "d.ps11test:11: probe failed: expected rgb 0x000000ff tol 0, pixel (2, 0) is 0xff000000 (4 pixels differ) (hardware geforce4 (1.1-class), fx8, max value 1)" "pixel probe failure"
expect_in "$work/out" "probes: 2 passed, 1 failed, 0 todo" "pixel probe counts"
expect_in "$work/out" "1 draws, " "draw --stats"
{
    printf '[texture 4]\nsize 1 1\nfill 0xffffffff\n'
    for i in 0 1 2 3; do printf '[stage %d]\ncolorop selectarg1\ncolorarg1 diffuse\n' "$i"; done
    printf '[stage 4]\ncolorop selectarg1\ncolorarg1 texture\n[test]\ndraw quad\nprobe 0 0 rgba 0xffffffff\n'
} >"$work/ff.ps11test"
expect_rc 1 "a draw the device refuses" "$ps11" test "$work/ff.ps11test"
expect_in "$work/out" "ff.ps11test:20: E4142 DrawPrimitiveUP" "device error names the draw's line"

# test: a folder stands for every .ps11test below it.
mkdir -p "$work/suite/sub" "$work/empty"
cp "$work/d.ps11test" "$work/suite/sub/"
printf '[pixel shader]\nps_1_1\nmov r0, v0\n[test]\neval\n  v0 1 0 0 1\nprobe eval rgba 1 0 0 1\n' >"$work/suite/e.ps11test"
expect_rc 1 "test on a folder" "$ps11" test "$work/suite"
expect_in "$work/out" "2 files: 1 passed, 1 failed" "a folder's files all run"
expect_rc 1 "test on a folder without test files" "$ps11" test "$work/empty"
expect_in "$work/err" "no .ps11test files under" "empty folder named"

# test --hardware: a class that cannot run the file is skipped; all runs every class.
printf '[pixel shader]\nps_1_2\nmov r0, v0\n[test]\neval\n  v0 1 0 0 1\nprobe eval rgba 1 0 0 1\n' >"$work/h.ps11test"
expect_rc 0 "test --hardware all" "$ps11" test --hardware all "$work/h.ps11test"
expect_in "$work/out" "geforce3: 1 file: 0 passed, 0 failed, 0 not yet runnable; probes: 0 passed, 0 failed, 0 todo; 1 skipped" "geforce3 skips ps_1_2"
expect_in "$work/out" "d3d9: 1 file: 1 passed" "d3d9 runs it"
printf '[require]\nhardware geforce3\n[pixel shader]\nps_1_2\nmov r0, v0\n' >"$work/h3.ps11test"
expect_rc 1 "test [require] hardware beyond the version" "$ps11" test "$work/h3.ps11test"
expect_in "$work/out" "h3.ps11test:2: hardware geforce3 runs ps_1_1 ... ps_1_1, but the file needs ps_1_2" "the [require] line named"
expect_rc 2 "test unknown class" "$ps11" test --hardware voodoo "$work/h.ps11test"

# demo: the report and its usage errors (the page itself: tests/cli/report_page.sh).
expect_rc 0 "demo --quick" "$ps11" demo --quick --size 64x36 --threads 1 --hardware geforce3 --out "$work/demo"
expect_in "$work/out" "report: $work/demo/index.html" "demo names its report"
expect_in "$work/out" "emulated geforce3" "demo runs --hardware"
for id in techniques fits agreement bench stress debug photos; do
    expect_in "$work/demo/index.html" "<section id=\"$id\">" "demo report section $id"
done
for t in adaptive glow pyramid quarter sprites; do
    [ -s "$work/demo/img/$t-emulated.png" ] && [ -s "$work/demo/img/$t-ideal.png" ] && [ -s "$work/demo/img/$t-input.png" ] ||
        fail "demo wrote no images for $t"
done
expect_in "$work/demo/index.html" "sensors need vertex texture fetch (vs_3_0)" "demo's fits table names the non-1.1 step"
expect_in "$work/err" "stress:" "demo progress on stderr"
expect_rc 2 "demo unknown class" "$ps11" demo --hardware voodoo
expect_rc 2 "demo bad size" "$ps11" demo --size 0x5
expect_in "$work/err" "sides 8..8192, not '0x5'" "demo states the size rule"
expect_rc 2 "demo size below a glare frame's least" "$ps11" demo --size 7x100
expect_rc 2 "bench size below a glare frame's least" "$ps11" bench --technique adaptive --size 100x7
expect_in "$work/err" "--size takes WxH with sides 8..8192, not '100x7'" "bench states the size rule"
expect_rc 2 "glare size above the largest" "$ps11" glare --technique adaptive --scene box --size 8193x8 -o "$work/never.png"
expect_in "$work/err" "--size takes WxH with sides 1..8192" "glare states the size rule"
expect_rc 2 "demo bad threads" "$ps11" demo --threads many
expect_rc 2 "demo unknown argument" "$ps11" demo --bogus
expect_in "$work/err" "unknown argument" "demo names the bad argument"

# Usage errors: exit 2.
expect_rc 2 "no command" "$ps11"
expect_rc 2 "unknown command" "$ps11" frobnicate
expect_in "$work/err" "ps11: unknown command 'frobnicate'" "unknown command named"
grep -q "did you mean" "$work/err" && fail "no suggestion expected for frobnicate"
expect_rc 2 "mistyped command" "$ps11" asmm "$work/a.psh"
expect_in "$work/err" "ps11: unknown command 'asmm'; did you mean 'asm'?" "command suggestion"
expect_rc 2 "unknown option" "$ps11" asm "$work/a.psh" --bogus
expect_rc 2 "mistyped option" "$ps11" asm "$work/a.psh" --hx
expect_in "$work/err" "ps11: asm: unknown option '--hx'; did you mean '--hex'?" "option suggestion"
expect_rc 2 "mistyped test option" "$ps11" test "$work/t.ps11test" --stat
expect_in "$work/err" "did you mean '--stats'?" "test option suggestion"
expect_rc 0 "--version" "$ps11" --version
grep -qE '^ps11 [0-9]+\.[0-9]+\.[0-9]+$' "$work/out" || fail "--version printed '$(cat "$work/out")'"
cp "$work/out" "$work/version1"
expect_rc 0 "version" "$ps11" version
cmp -s "$work/out" "$work/version1" || fail "'ps11 version' and 'ps11 --version' differ"
expect_rc 0 "help lists --version" "$ps11" help
expect_in "$work/out" "--version" "usage mentions --version"
expect_rc 2 "asm without input" "$ps11" asm
expect_rc 2 "-D without name" "$ps11" asm "$work/a.psh" -D
expect_rc 0 "help" "$ps11" --help

# ps11 info: the build and the OpenGL context (docs/gl-backend.md "Contexts"). Both kinds work on
# Debian 12 with .ci/setup's packages; a build without them (PS11_GL=OFF) reports that instead.
expect_rc 0 "info" "$ps11" info
expect_in "$work/out" "$(cat "$work/version1")" "info prints the version"
expect_in "$work/out" "default hardware: geforce4" "info names the default hardware class"
expect_in "$work/out" "executor kernels: " "info names the executor kernels"
expect_in "$work/out" "simd level: " "info names the SIMD level"
# PS11_SIMD forces a SIMD level (docs/architecture.md "SIMD dispatch"); a value it does not know
# is named on stderr and the best level is used.
expect_rc 0 "info at the baseline level" env PS11_SIMD=baseline "$ps11" info
expect_in "$work/out" "simd level: baseline" "PS11_SIMD=baseline is the level in use"
expect_rc 0 "info with an unknown PS11_SIMD" env PS11_SIMD=bogus "$ps11" info
expect_in "$work/err" "ps11: PS11_SIMD=bogus: unknown SIMD level" "an unknown PS11_SIMD is reported"
expect_in "$work/out" "simd level: " "an unknown PS11_SIMD still gives a level"
expect_rc 0 "info --json" "$ps11" info --json
expect_in "$work/out" '"hardware": "geforce4"' "info --json"
expect_json "$work/out" "info --json"
if grep -q "PS11_GL=OFF" "$work/out"; then
    expect_rc 1 "info --gl egl without the GL backend" "$ps11" info --gl egl
else
    expect_in "$work/out" '"GL_RENDERER": ' "info --json has the GL context"
    expect_rc 0 "info --gl egl" "$ps11" info --gl egl
    expect_in "$work/out" "GL context: egl (EGL " "info --gl egl names the kind and platform"
    expect_in "$work/out" "GL_RENDERER: " "info --gl egl prints GL_RENDERER"
    expect_in "$work/out" "GL_VERSION: " "info --gl egl prints GL_VERSION"
    # Without an EGL vendor library (GLVND finds none), --gl egl is the user's error, named.
    expect_rc 1 "info --gl egl without a vendor" env __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json "$ps11" info --gl egl
    expect_in "$work/err" "ps11: info: EGL: " "the EGL failure is named"
    "$ps11" info --gl osmesa >"$work/out" 2>&1
    if ! grep -q "PS11_GL_OSMESA=OFF" "$work/out"; then
        expect_rc 0 "info --gl osmesa" "$ps11" info --gl osmesa
        expect_in "$work/out" "GL context: osmesa (OSMesa)" "info --gl osmesa"
        # Mesa capped below 3.3: the core profile request is refused, and said so.
        expect_rc 1 "info --gl osmesa below 3.3" env MESA_GL_VERSION_OVERRIDE=3.1 "$ps11" info --gl osmesa
        expect_in "$work/err" "ps11: info: OSMesa: OSMesaCreateContextAttribs refused" "the OSMesa failure is named"
        # Without --gl, no context is still a report, not an error.
        expect_rc 0 "info without any context" env MESA_GL_VERSION_OVERRIDE=3.1 \
            __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json "$ps11" info
        expect_in "$work/out" "GL context: none (OSMesa: " "info reports why there is no context"
    fi
fi
# The GL renderer: ps11 test --backend gl|both and ps11 compare (docs/gl-backend.md "Cross-check").
if ! grep -q "PS11_GL=OFF" <("$ps11" info 2>&1); then
    printf '[require]\nversion ps_1_1\n\n[render target]\nsize 4 4\n\n[texture 0]\nsize 2 2\nformat A8R8G8B8\nlevel 0\n0xff102030 0xff405060\n0xff708090 0xffa0b0c0\n\n[sampler 0]\nfilter linear\n\n[pixel shader]\nps_1_1\ntex t0\nmul_x2 r0, t0, v0\n\n[test]\ndraw quad\neval\n  v0 0.5 0.25 1 1\n  t0 0.25 0.75\nprobe eval rgba 0.25 0.25 0.25 1 tol 1\n' >"$work/x.ps11test"
    expect_rc 0 "test --backend both" "$ps11" test --backend both "$work/x.ps11test"
    expect_in "$work/out" "cross-check (" "test --backend both prints the cross-check"
    expect_in "$work/out" "2 draws, 17 pixels, 17 exact (100 %), 0 past the target, max |d| 0; 0 disagreements" "draw and eval agree"
    expect_rc 0 "test --backend gl --gl egl" "$ps11" test --backend gl --gl egl "$work/x.ps11test"
    expect_rc 2 "test --gl unknown kind" "$ps11" test --gl glx "$work/x.ps11test"
    expect_in "$work/err" "unknown GL context 'glx'" "test names the GL kinds"
    expect_rc 1 "test --backend gl without a context" env MESA_GL_VERSION_OVERRIDE=3.1 \
        __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json "$ps11" test --backend gl "$work/x.ps11test"
    expect_in "$work/err" "ps11 test: --backend gl: no GL renderer: " "no GL renderer is the user's error, named"
    expect_rc 0 "compare a test file" "$ps11" compare "$work/x.ps11test" --json
    expect_in "$work/out" '"pixels": 16, "exact": 16, "over_one": 0, "max_diff": 0, "draws": [{"line": ' "compare --json totals"
    expect_in "$work/out" '"unsupported": []' "compare --json lists nothing unsupported"
    expect_json "$work/out" "compare --json"
    printf 'ps_1_1\ntex t0\ntexbem t1, t0\nmad r0, t1, v0, c0\n' >"$work/bem.psh"
    expect_rc 0 "compare a bare shader" "$ps11" compare "$work/bem.psh" --size 16x8 --seed 7 --heatmap "$work/heat.png"
    expect_in "$work/out" "128 pixels, 128 exact" "compare draws the shader over random inputs"
    [ "$(head -c 8 "$work/heat.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "compare --heatmap wrote no PNG"
    expect_rc 0 "compare --random" "$ps11" compare --random 3 --seed 11 --out "$work"
    expect_in "$work/out" "random: 3 programs (seeds 11..13)" "compare --random counts its programs"
    expect_rc 1 "compare an invalid shader" "$ps11" compare "$work/bad.psh"
    expect_in "$work/err" "bad.psh:3:9: error P2090" "compare names the shader's error"
    expect_rc 1 "compare a missing file" "$ps11" compare "$work/none.ps11test"
    expect_in "$work/err" "none.ps11test" "compare names the missing file"
    expect_rc 1 "compare --heatmap into a missing folder" "$ps11" compare "$work/bem.psh" --heatmap "$work/no/dir/h.png"
    expect_in "$work/err" "no/dir/h.png" "the heat map's path is named"
fi
expect_rc 2 "compare without input" "$ps11" compare
expect_in "$work/err" "missing SHADER.psh or FILE.ps11test" "compare says what is missing"
expect_rc 2 "compare --size bad" "$ps11" compare x.psh --size 0x4
expect_in "$work/err" "--size takes WxH with sides 1..4096" "compare states its size rule"
expect_rc 2 "compare --random with a file" "$ps11" compare x.psh --random 3
expect_rc 2 "compare unknown option" "$ps11" compare x.psh --heatmpa h.png
expect_in "$work/err" "did you mean '--heatmap'?" "compare suggests the option"
expect_rc 2 "info --gl unknown kind" "$ps11" info --gl glx
expect_in "$work/err" "ps11: info: --gl takes osmesa or egl, not 'glx'" "info names the kinds"

# ps11 shade and ps11 glare (docs/glare/README.md).
printf 'ps_1_1\nmov r0, c0\n' >"$work/flat.psh"
expect_rc 0 "shade a constant" "$ps11" shade "$work/flat.psh" --c0 0.5,0.25,1,1 --size 24x16 -o "$work/flat.png"
expect_in "$work/out" "wrote $work/flat.png (24x16)" "shade reports the image"
printf 'ps_1_1\ntex t0\nmul_x2 r0, t0, c0\n' >"$work/tex.psh"
expect_rc 0 "shade an image" "$ps11" shade "$work/tex.psh" --tex0 "$work/flat.png" --filter0 point --c0 1,1,1,1 -o "$work/tex.png"
expect_in "$work/out" "(24x16)" "shade takes texture 0's size"
printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n\200\100\040\201\200\100\040\201\200\100\040\201\200\100\040\201' >"$work/tiny.hdr"
expect_rc 0 "shade an HDR image" "$ps11" shade "$work/tex.psh" --tex0 "$work/tiny.hdr" --exposure -1 --c0 0.5,0.5,0.5,1 -o "$work/hdr.png"
expect_in "$work/out" "(2x2)" "shade reads Radiance .hdr"
expect_rc 1 "shade an invalid shader" "$ps11" shade "$work/bad.psh" --size 4x4 -o "$work/x.png"
expect_in "$work/err" "bad.psh:3:9" "shade names the shader's place"
expect_rc 1 "shade a missing image" "$ps11" shade "$work/tex.psh" --tex0 "$work/none.png" -o "$work/x.png"
expect_in "$work/err" "none.png" "shade names the missing image"
head -c 20 "$work/flat.png" >"$work/cut.png"
expect_rc 1 "shade a truncated PNG" "$ps11" shade "$work/tex.psh" --tex0 "$work/cut.png" -o "$work/x.png"
expect_in "$work/err" "cut.png: truncated PNG" "a truncated PNG is named"
expect_rc 2 "shade without -o" "$ps11" shade "$work/tex.psh" --tex0 "$work/flat.png"
expect_rc 2 "shade --c9" "$ps11" shade "$work/tex.psh" --c9 1,1,1,1 -o "$work/x.png"
expect_rc 2 "shade bad constant" "$ps11" shade "$work/tex.psh" --c0 1,2 -o "$work/x.png"
expect_in "$work/err" "--c0 takes four numbers" "shade explains the constant"

expect_rc 0 "glare --list" "$ps11" glare --list
for t in adaptive glow pyramid quarter sprites; do expect_in "$work/out" "$t " "glare --list names $t"; done
expect_in "$work/out" "box " "glare --list names the scenes"
expect_rc 0 "glare --report --json" "$ps11" glare --report --json
python3 -c 'import json, sys; assert json.load(open(sys.argv[1]))["passes"]' "$work/out" || fail "glare --report --json is not JSON"
expect_in "$work/out" '"pass": "sensors", "kind": "device side"' "the report labels the device-side step"
expect_in "$work/out" '"fits_ps_1_1": false' "the report says what does not fit"
expect_rc 0 "glare on a scene" "$ps11" glare --technique adaptive --scene box --size 64x36 --frames 2 -o "$work/g.png"
[ -s "$work/g_0000.png" ] && [ -s "$work/g_0001.png" ] || fail "glare --frames 2 did not write g_0000.png and g_0001.png"
expect_in "$work/out" "bright_pass" "glare prints its passes"
expect_in "$work/out" "  median  draws" "glare prints each pass's median over the frames"
expect_rc 0 "glare on an image, dumped" "$ps11" glare --technique quarter --in "$work/tex.png" --dump-passes "$work/dump" -o "$work/q.png"
[ -s "$work/dump/contact_sheet.png" ] && [ -s "$work/dump/00_downsample-quarter.png" ] || fail "glare --dump-passes wrote no pass images"
expect_rc 0 "glare on a held image, reused" "$ps11" glare --technique glow --in "$work/tex.png" --frames 3 -o "$work/r.png"
expect_in "$work/out" "  reused" "glare reuses passes of a still image"
cp "$work/r_0002.png" "$work/r_reused.png"
expect_rc 0 "glare --no-skip" "$ps11" glare --technique glow --in "$work/tex.png" --frames 3 --no-skip -o "$work/r.png"
if grep -q "  reused -$" "$work/out"; then fail "glare --no-skip reused a pass"; fi
expect_in "$work/out" "tiles shaded/filled/copied/skipped" "glare prints the tile decisions"
cmp -s "$work/r_0002.png" "$work/r_reused.png" || fail "glare: the reused frame differs from the --no-skip one"
expect_rc 0 "glare --json says reused" "$ps11" glare --technique glow --in "$work/tex.png" --frames 2 --json -o "$work/r.png"
expect_in "$work/out" '"reused": true' "glare --json reused"
expect_json "$work/out" "glare --json"
# Each pass's median over the frames that ran it: glow's first frame runs every pass, its second reuses
# them, so every pass ran in exactly one frame.
python3 -c 'import json, sys; p = json.load(open(sys.argv[1]))["passes"]; assert p and all(x["frames_run"] == 1 and x["median_ms"] >= 0 for x in p)' "$work/out" || fail "glare --json: median_ms and frames_run of a reused pass"
# --in DIR: each image file of the folder in turn, sorted, outputs named after the image.
mkdir -p "$work/photos/sub.png" "$work/glare_out" "$work/no_photos"
cp "$work/tex.png" "$work/photos/b.png"
{ printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 8\n'; for _ in $(seq 64); do printf '\200\100\040\201'; done; } >"$work/photos/A.hdr"
echo "not an image" >"$work/photos/notes.txt"
expect_rc 0 "glare --in a folder" "$ps11" glare --technique quarter --in "$work/photos" -o "$work/glare_out/q.png" --dump-passes "$work/glare_out/d"
expect_in "$work/out" "== $work/photos/A.hdr (1 of 2)" "glare --in DIR runs the first image (sorted)"
expect_in "$work/out" "== $work/photos/b.png (2 of 2)" "glare --in DIR runs the second image"
expect_in "$work/out" "quarter on 24x16 ($work/photos/b.png)" "glare --in DIR runs each image at its size"
[ -s "$work/glare_out/q_A.png" ] && [ -s "$work/glare_out/q_b.png" ] || fail "glare --in DIR did not write q_A.png and q_b.png"
[ -s "$work/glare_out/d/A/contact_sheet.png" ] && [ -s "$work/glare_out/d/b/contact_sheet.png" ] || fail "glare --in DIR: no dump folder per image"
[ "$(find "$work/glare_out" -maxdepth 1 -name '*.png' | wc -l)" = 2 ] || fail "glare --in DIR wrote other images than one per picture"
expect_rc 0 "glare --in a folder --json" "$ps11" glare --technique quarter --in "$work/photos" -o "$work/glare_out/q.png" --json
python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); assert [r["size"] for r in d] == [[8, 8], [24, 16]], d' "$work/out" ||
    fail "glare --in DIR --json: not an array of each image's object"
expect_rc 1 "glare --in an empty folder" "$ps11" glare --technique quarter --in "$work/no_photos" -o "$work/x.png"
expect_in "$work/err" "$work/no_photos: no image files (*.png, *.hdr, *.exr) in the folder" "glare --in DIR says it found none"
printf 'v/1\001\002' >"$work/no_photos/broken.exr"
expect_rc 1 "glare --in a folder with a broken image" "$ps11" glare --technique quarter --in "$work/no_photos" -o "$work/x.png"
expect_in "$work/err" "$work/no_photos/broken.exr: " "glare --in DIR names the image that failed"
expect_rc 0 "bench --in a folder" "$ps11" bench --technique quarter --in "$work/photos" --frames 1 --backend emu
expect_in "$work/out" "$work/photos/A.hdr" "bench --in DIR has rows of the first image"
expect_in "$work/out" "$work/photos/b.png" "bench --in DIR has rows of the second image"
expect_rc 0 "glare --graph without -o" "$ps11" glare --technique pyramid --scene sky --size 64x36 --graph "$work/p.dot"
expect_in "$work/p.dot" 'digraph "pyramid"' "glare --graph writes Graphviz"
expect_rc 0 "glare --graph with -o" "$ps11" glare --technique pyramid --scene sky --size 64x36 --graph "$work/p2.dot" -o "$work/p2.png"
expect_in "$work/p2.dot" 'device texture #0' "glare --graph with -o writes the graph as it ran (device textures)"
expect_rc 0 "glare --json" "$ps11" glare --technique glow --scene neon --size 64x36 --set path=ffp -o "$work/f.png" --json
expect_in "$work/out" '"pass": "blur_h_0"' "glare --json lists the passes"
expect_rc 2 "glare unknown technique" "$ps11" glare --technique bloom --scene box -o "$work/x.png"
expect_in "$work/err" "unknown technique 'bloom' (techniques: adaptive, glow, pyramid, quarter, sprites)" "glare lists the techniques"
expect_rc 2 "glare two inputs" "$ps11" glare --technique glow --scene box --in "$work/tex.png" -o "$work/x.png"
expect_rc 2 "glare unknown scene" "$ps11" glare --technique glow --scene moon -o "$work/x.png"
expect_in "$work/err" "unknown scene 'moon'" "glare names the scenes"
expect_rc 2 "glare --set unknown" "$ps11" glare --technique glow --scene box --set radious=3 -o "$work/x.png"
expect_in "$work/err" "technique glow has no setting 'radious'" "glare names the setting"
expect_rc 2 "glare --set out of range" "$ps11" glare --technique glow --scene box --set radius=99 -o "$work/x.png"
expect_in "$work/err" "setting radius: 99 is outside the whole numbers 1 .. 32 texels" "glare gives the range"
expect_rc 2 "glare --set bad choice" "$ps11" glare --technique adaptive --scene box --set composite=multiply -o "$work/x.png"
expect_in "$work/err" "is not one of screen, add, luminance" "glare lists the choices"
expect_rc 2 "glare --quality" "$ps11" glare --technique glow --scene box --quality ultra -o "$work/x.png"
expect_rc 1 "glare a missing image" "$ps11" glare --technique glow --in "$work/none.exr" -o "$work/x.png"
expect_in "$work/err" "none.exr" "glare names the missing image"
expect_rc 1 "glare an image too small" "$ps11" glare --technique glow --in "$work/hdr.png" -o "$work/x.png"
expect_in "$work/err" "at least 8x8" "glare says the frame is too small"

# --no-skip on shade and test: every tile drawn (docs/device.md "Tile skipping"), the same images.
expect_rc 0 "shade a constant, tiles skipped" "$ps11" shade "$work/flat.psh" --c0 0.5,0.25,1,1 --size 200x100 -o "$work/ns_flat.png"
expect_rc 0 "shade a constant --no-skip" "$ps11" shade "$work/flat.psh" --c0 0.5,0.25,1,1 --size 200x100 --no-skip -o "$work/ns_flat_all.png"
cmp -s "$work/ns_flat.png" "$work/ns_flat_all.png" || fail "shade --no-skip wrote another image (constant)"
expect_rc 0 "shade an image, tiles skipped" "$ps11" shade "$work/tex.psh" --tex0 "$work/g_0000.png" --c0 0.5,1,1,1 --size 300x170 -o "$work/ns_tex.png"
expect_rc 0 "shade an image --no-skip" "$ps11" shade "$work/tex.psh" --tex0 "$work/g_0000.png" --c0 0.5,1,1,1 --size 300x170 --no-skip -o "$work/ns_tex_all.png"
cmp -s "$work/ns_tex.png" "$work/ns_tex_all.png" || fail "shade --no-skip wrote another image (texture)"
expect_rc 2 "shade --no-skip mistyped" "$ps11" shade "$work/flat.psh" --size 4x4 --no-skp -o "$work/x.png"
expect_in "$work/err" "did you mean '--no-skip'?" "shade suggests --no-skip"
corpus_file="$root/tests/shaders/draw/address_wrap_linear.ps11test"
expect_rc 0 "test a corpus file --stats" "$ps11" test "$corpus_file" --stats
expect_in "$work/out" "tiles shaded/filled/copied/skipped " "test --stats prints the tile decisions"
if grep -q "tiles shaded/filled/copied/skipped 0/0/0/0" "$work/out"; then fail "test: the corpus file's draw was not tiled"; fi
expect_rc 0 "test a corpus file --no-skip" "$ps11" test "$corpus_file" --no-skip --stats
expect_in "$work/out" "1 file: 1 passed, 0 failed" "test --no-skip passes"
# (Its program copies one tap whatever it reads: drawn as that copy, skipping on or off, no lane shaded.)
expect_in "$work/out" "0 pixels shaded, 32 written" "test --no-skip draws every pixel"
expect_in "$work/out" "tiles shaded/filled/copied/skipped 0/0/0/0" "test --no-skip cuts no tiles"
expect_rc 0 "test the draw corpus --no-skip" "$ps11" test "$root/tests/shaders/draw" --no-skip
expect_in "$work/out" " passed, 0 failed, 0 not yet runnable" "the draw corpus passes with --no-skip"
if ! grep -q "PS11_GL=OFF" <("$ps11" info 2>&1); then
    expect_rc 0 "glare --compare" "$ps11" glare --technique adaptive --scene box --size 64x36 --compare
    expect_in "$work/out" "agreement: every pass within 1 level" "glare --compare agrees"
    # End to end (not pass-isolated): the whole frame drawn on GL is the emulator's, byte for byte.
    expect_rc 0 "glare --backend gl" "$ps11" glare --technique pyramid --scene sky --size 64x36 --backend gl -o "$work/pgl.png"
    expect_rc 0 "glare --backend emu" "$ps11" glare --technique pyramid --scene sky --size 64x36 -o "$work/pemu.png"
    cmp -s "$work/pgl.png" "$work/pemu.png" || fail "glare --backend gl wrote another image than the emulator"
    expect_rc 2 "glare --compare with --backend" "$ps11" glare --technique pyramid --scene sky --compare --backend gl
    expect_rc 0 "glare --compare --json" "$ps11" glare --technique sprites --scene lights --size 64x36 --compare --json
    expect_in "$work/out" '"pass": "draw_sprites", "pixels": 2304, "exact": 2304, "over_one": 0' "glare --compare --json per pass"
    expect_json "$work/out" "glare --compare --json"
    # The GL renderer's two modes (docs/gl-backend.md "Modes").
    expect_rc 0 "info lists the GL modes" "$ps11" info
    expect_in "$work/out" "GL renderer modes: exact" "info names the exact mode"
    expect_in "$work/out" "native (GL's own interpolation" "info names the native mode"
    expect_rc 0 "glare --backend gl table" "$ps11" glare --technique pyramid --scene sky --size 64x36 --backend gl --no-skip -o "$work/pgl.png"
    expect_in "$work/out" "0 uploaded, 1 read back" "a glare frame on GL reads back once and uploads nothing"
    expect_rc 0 "glare --backend gl with reuse" "$ps11" glare --technique pyramid --scene sky --size 64x36 --backend gl -o "$work/pgl.png"
    expect_in "$work/out" "0 uploaded," "a glare frame on GL with reuse uploads nothing"
    expect_rc 0 "glare --gl-mode native" "$ps11" glare --technique glow --scene neon --size 64x36 --backend gl --gl-mode native -o "$work/gn.png"
    expect_in "$work/out" "gl-native renderer" "glare names the native renderer"
    expect_rc 0 "glare --compare --gl-mode native" "$ps11" glare --technique quarter --scene neon --size 64x36 --compare --gl-mode native --json
    python3 - "$work/out" <<'PY' || fail "glare native distances in JSON: $(head -c 400 "$work/out")"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["gl_mode"] == "native"
assert all(k in j["end_to_end"][ref] for ref in ("vs_card", "vs_ideal") for k in ("max_levels", "mean_levels", "over_one_pct"))
PY
    expect_rc 2 "glare --gl-mode without gl" "$ps11" glare --technique glow --scene neon --gl-mode native -o "$work/x.png"
    expect_in "$work/err" "--gl-mode needs --backend gl or --compare" "glare says what --gl-mode needs"
    expect_rc 2 "glare --gl-mode bad" "$ps11" glare --technique glow --scene neon --backend gl --gl-mode fast -o "$work/x.png"
    expect_in "$work/err" "--gl-mode takes exact or native" "glare lists the modes"
    printf '[render target]\nsize 4 2\nclear 0xff000000\n[pixel shader]\nps_1_1\nmov r0, v0\n[test]\ndraw quad diffuse 0xff0000ff\nprobe all rgba 0xff0000ff\n' >"$work/n.ps11test"
    expect_rc 0 "test --gl-mode native" "$ps11" test "$work/n.ps11test" --backend both --gl-mode native
    expect_in "$work/out" "gl native mode, measured against the emulated card: 0 probes differ" "test counts native differences"
    expect_rc 2 "test --gl-mode without gl" "$ps11" test "$work/d.ps11test" --gl-mode native
    expect_rc 0 "test --backend both --no-skip" "$ps11" test "$corpus_file" --backend both --no-skip
    expect_in "$work/out" "0 disagreements" "--no-skip on the emu side agrees with gl"
    expect_rc 0 "compare --gl-mode native" "$ps11" compare "$work/n.ps11test" --gl-mode native
    expect_in "$work/out" "gl native against ideal: max |d| 0 levels" "compare reports the distance from ideal"
    expect_rc 0 "bench --backend both" "$ps11" bench --technique quarter --size 64x36 --frames 1 --backend both --json
    expect_in "$work/out" '"backend": "gl"' "bench runs a GL row"
    expect_in "$work/out" '"gl_mode": "native"' "bench's GL rows run native mode by default"
    expect_rc 0 "bench --gl-mode exact" "$ps11" bench --technique quarter --size 64x36 --frames 1 --backend gl --gl-mode exact
    expect_in "$work/out" "gl-exact" "bench names the exact mode"
    expect_rc 2 "bench --gl-mode without gl" "$ps11" bench --backend emu --gl-mode exact
    expect_in "$work/err" "--gl-mode needs --backend gl or both" "bench says what --gl-mode needs"
    expect_rc 2 "compare --random --gl-mode native" "$ps11" compare --random 2 --gl-mode native
    expect_rc 0 "shade --gl-mode native" "$ps11" shade "$work/a.psh" --tex0 "$work/tex.png" --backend gl --gl-mode native -o "$work/sn.png"
    expect_rc 2 "shade --gl-mode without gl" "$ps11" shade "$work/a.psh" --tex0 "$work/tex.png" --gl-mode native -o "$work/sn.png"
fi

# ps11 stress (docs/stress.md): valid JSON with every item of the issue, numbers or objects of
# numbers (null where not measured), and every robustness check passing.
expect_rc 0 "stress --json" "$ps11" stress --json --size 128
python3 - "$work/out" <<'PY' || fail "stress --json: $(head -c 400 "$work/out")"
import json, numbers, sys
d = json.load(open(sys.argv[1]))
names = [i["name"] for i in d["items"]]
want = ["smoothing_dead_band", "blur_energy_drift", "weight_sum_rounded", "weight_sum_diffused",
        "feedback_residue", "decimation_capture"]
assert names == want, names
def value(v):
    return v is None or isinstance(v, numbers.Number) or (
        isinstance(v, dict) and all(x is None or isinstance(x, numbers.Number) for x in v.values()))
for i in d["items"]:
    assert all(k in i for k in ("predicted", "measured", "fix", "measured_with_fix")), i["name"]
    assert value(i["predicted"]) and value(i["measured"]) and value(i["measured_with_fix"]), i["name"]
assert {m["technique"] for m in d["metrics"]} == {"adaptive", "glow", "pyramid", "quarter", "sprites"}
assert d["robustness"] and all(c["pass"] for c in d["robustness"])
PY
expect_rc 2 "stress --size 100" "$ps11" stress --size 100
expect_rc 2 "stress unknown option" "$ps11" stress --jsn
expect_in "$work/err" "--json" "stress suggests --json"

if [ "$failures" != 0 ]; then
    echo "$failures CLI check(s) failed"
    exit 1
fi
echo "all CLI checks passed"
