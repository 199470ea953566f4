#!/usr/bin/env bash
# ps11 as a library (docs/api.md), end to end: installs BUILD_DIR into a temporary prefix, checks
# that the installed headers include only installed headers (never the .ps11test model), then
# configures, builds and runs examples/embed against the installed package.
#   embed_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src="$(cd "$1" && pwd)"
build="$(cd "$2" && pwd)"
prefix="$(mktemp -d)"
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" >/dev/null

# Every #include "x" of an installed header names an installed header.
bad=0
while IFS= read -r header; do
    while IFS= read -r inc; do
        if [ ! -f "$prefix/include/$inc" ]; then
            echo "embed: ${header#"$prefix"/} includes $inc, which is not installed" >&2
            bad=1
        fi
    done < <(sed -n 's/^#include "\([^"]*\)".*/\1/p' "$header")
done < <(find "$prefix/include" -name '*.h')
[ "$bad" = 0 ] || exit 1
echo "embed: $(find "$prefix/include" -name '*.h' | wc -l) public headers, all self-contained in the prefix"

cmake -S "$src/examples/embed" -B "$prefix/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$prefix/build" -j2 >/dev/null
"$prefix/build/shade_quad"
"$prefix/build/glare_image" "$prefix/glare.png"
test -s "$prefix/glare.png"
echo "embed: ok"
