#!/usr/bin/env bash
# End-to-end checks of the ps11 command line: outputs, exit codes (0 ok, 1 user error,
# 2 usage) and that user errors name the file and place. Usage: cli_test.sh PATH/TO/ps11
set -u
ps11="$1"
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
expect_in "$work/out" '"arithSlots":1' "check --json"
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

# Usage errors: exit 2.
expect_rc 2 "no command" "$ps11"
expect_rc 2 "unknown command" "$ps11" frobnicate
expect_rc 2 "unknown option" "$ps11" asm "$work/a.psh" --bogus
expect_rc 2 "asm without input" "$ps11" asm
expect_rc 2 "-D without name" "$ps11" asm "$work/a.psh" -D
expect_rc 0 "help" "$ps11" --help

if [ "$failures" != 0 ]; then
    echo "$failures CLI check(s) failed"
    exit 1
fi
echo "all CLI checks passed"
