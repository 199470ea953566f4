#!/usr/bin/env bash
# A doc example is a test: every ```ps11test block in README.md and docs/*.md is written to a
# file of its own and run by `ps11 test`; each must parse, and every probe in it must pass.
# Usage: doc_examples.sh PATH/TO/ps11 PROJECT_DIR
set -u
ps11="$1"
root="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for doc in "$root"/README.md "$root"/docs/*.md; do
    awk -v dir="$work" -v base="$(basename "$doc" .md)" '
        /^```ps11test[[:space:]]*$/ { n++; f = sprintf("%s/%s-%02d.ps11test", dir, base, n); inb = 1; next }
        /^```[[:space:]]*$/ { inb = 0; next }
        inb { print > f }' "$doc"
done
files=("$work"/*.ps11test)
if [ ! -e "${files[0]}" ]; then
    echo "no ps11test examples found under $root"
    exit 1
fi
echo "${#files[@]} doc examples"
"$ps11" test "${files[@]}"
