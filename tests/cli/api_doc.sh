#!/usr/bin/env bash
# docs/api.md shows the embed example's files verbatim: every block after a line
# `<!-- file: PATH -->` must equal PATH (relative to the source tree). With --update, rewrites
# those blocks from the files instead of checking them.
#   api_doc.sh SOURCE_DIR [--update]
set -euo pipefail
src="$1"
doc="$src/docs/api.md"
out="$(mktemp)"
trap 'rm -f "$out"' EXIT
# Writes the document with every marked block replaced by its file.
awk -v src="$src" '
    /^<!-- file: .* -->$/ { path = $3; print; marked = 1; next }
    marked && /^```/ { print; while ((getline line < (src "/" path)) > 0) print line; close(src "/" path);
                       skipping = 1; marked = 0; next }
    skipping { if ($0 ~ /^```$/) { print; skipping = 0 } ; next }
    { print }
' "$doc" > "$out"
blocks="$(grep -c '^<!-- file: ' "$doc" || true)"
if [ "$blocks" -eq 0 ]; then
    echo "api_doc: $doc has no <!-- file: PATH --> blocks" >&2
    exit 1
fi
if [ "${2:-}" = "--update" ]; then
    cp "$out" "$doc"
    echo "api_doc: $doc: $blocks blocks written"
    exit 0
fi
if ! diff -u "$doc" "$out"; then
    echo "api_doc: docs/api.md differs from the example files (bash tests/cli/api_doc.sh . --update)" >&2
    exit 1
fi
echo "api_doc: $blocks blocks match their files"
