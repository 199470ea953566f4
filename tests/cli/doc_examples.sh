#!/usr/bin/env bash
# A doc example is a test: every ```ps11test block in README.md and docs/*.md is written to a
# file of its own and run by `ps11 test`; each must parse, and every probe in it must pass. Every
# ```sh block of README.md whose first line is `# tour...` runs line by line from the project's
# root with ./build/ps11 replaced by the ps11 under test; every command must succeed.
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
"$ps11" test "${files[@]}" || exit 1

# The README's tour.
awk '/^```sh[[:space:]]*$/ { inb = 1; first = 1; next }
     /^```[[:space:]]*$/ { inb = 0; tour = 0; next }
     inb && first { first = 0; tour = ($0 ~ /^# tour/) }
     inb && tour { print }' "$root/README.md" >"$work/tour.sh"
commands=$(grep -cv '^#' "$work/tour.sh")
[ "$commands" -gt 10 ] || { echo "FAIL: the README's tour has $commands commands"; exit 1; }
cd "$root" || exit 1
n=0
while IFS= read -r line; do
    case "$line" in "#"* | "") continue ;; esac
    n=$((n + 1))
    cmd="${line//.\/build\/ps11/\"$ps11\"}"
    if ! (set -o pipefail; eval "$cmd") >"$work/tour.out" 2>&1; then
        echo "FAIL: README tour command $n: $line"
        tail -5 "$work/tour.out"
        exit 1
    fi
done <"$work/tour.sh"
echo "README tour: $n commands ran"
