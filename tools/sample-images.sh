#!/usr/bin/env bash
# Fetches real HDR photographs from Debian packages into a cache outside the repository (never
# committed), for `ps11 glare --in DIR` and the demo (docs/images.md "Sample photographs"):
#
#   psychtoolbox-3-common  the OpenEXR sample images of Industrial Light & Magic (BSD-3-Clause):
#                          5 photographs and a synthetic gamut chart, PIZ and ZIP, scanline and
#                          tiled, 17.3 MB
#   blender-data           Blender's studio-light world HDRIs by Greg Zaal, HDRI Haven (CC0-1.0):
#                          8 equirectangular 1024x512 photographs, DWAB, 1.9 MB
#
# Each package is downloaded with `apt-get download` (no installation, no root needed unless the
# package lists must be updated) and only its image files and licence texts are extracted with
# `dpkg-deb`. The cache holds one folder per package, its licence texts and images.tsv, the manifest
# read by glare/photos.h: path (relative to the cache), package and version, licence (SPDX),
# description, separated by tabs.
#
# Usage: tools/sample-images.sh [--force]
#   The cache is $PS11_IMAGES, else ~/.cache/ps11/images. A package already extracted at the version
#   apt offers is kept (--force fetches it again). Needs apt-get and dpkg-deb (Debian 12 or later).
set -euo pipefail

force=0
case "${1:-}" in
    "") ;;
    --force) force=1 ;;
    -h | --help)
        sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'
        exit 0
        ;;
    *)
        echo "sample-images.sh: unknown option '$1' (--force, --help)" >&2
        exit 2
        ;;
esac

if [ -n "${PS11_IMAGES:-}" ]; then
    cache="$PS11_IMAGES"
elif [ -n "${HOME:-}" ]; then
    cache="$HOME/.cache/ps11/images"
else
    echo "sample-images.sh: neither PS11_IMAGES nor HOME is set; say where the images go with PS11_IMAGES=DIR" >&2
    exit 1
fi
for tool in apt-get apt-cache dpkg-deb tar; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        echo "sample-images.sh: $tool is missing; this script fetches Debian packages (Debian 12 or later)" >&2
        exit 1
    fi
done
mkdir -p "$cache"
work="$(mktemp -d "$cache/.fetch.XXXXXX")"
trap 'rm -rf "$work"' EXIT
# As root, apt-get download warns that its sandbox user (_apt) cannot write here and downloads as root.

# The version apt would download, or nothing when the package is unknown to it.
candidate() {
    apt-cache policy "$1" 2>/dev/null | awk '/Candidate:/ { if ($2 != "(none)") print $2; exit }'
}

updated=0
# Makes sure apt knows the package, updating its lists once if needed (as root, or through sudo).
known() {
    local package="$1"
    [ -n "$(candidate "$package")" ] && return 0
    if [ "$updated" = 0 ]; then
        updated=1
        echo "sample-images.sh: apt does not know $package; updating the package lists" >&2
        if [ "$(id -u)" = 0 ]; then
            apt-get update -qq >&2 || true
        elif command -v sudo >/dev/null 2>&1; then
            sudo apt-get update -qq >&2 || true
        else
            echo "sample-images.sh: cannot run apt-get update (not root, no sudo)" >&2
        fi
    fi
    [ -n "$(candidate "$package")" ]
}

# fetch PACKAGE DIR-IN-PACKAGE GLOB LICENCE-FILES...: downloads PACKAGE and extracts the files of
# DIR-IN-PACKAGE matching GLOB into $cache/PACKAGE/, and the licence files into $cache/PACKAGE/licence/.
# Prints the version extracted; nothing is changed when that version is already there.
fetch() {
    local package="$1" inside="$2" glob="$3"
    shift 3
    local version dest="$cache/$package"
    if ! known "$package"; then
        echo "sample-images.sh: apt has no package $package (is this Debian 12 or later with main enabled?)" >&2
        return 1
    fi
    version="$(candidate "$package")"
    if [ "$force" = 0 ] && [ -f "$dest/.version" ] && [ "$(cat "$dest/.version")" = "$version" ]; then
        echo "$version"
        return 0
    fi
    echo "sample-images.sh: downloading $package $version" >&2
    local dir="$work/$package"
    mkdir -p "$dir/x"
    # (errexit does not hold in a function called as a condition: each step says when it failed.)
    (cd "$dir" && apt-get download -q "$package=$version" >&2) || return 1
    local deb
    deb="$(find "$dir" -maxdepth 1 -name '*.deb' -print -quit)"
    [ -n "$deb" ] || { echo "sample-images.sh: apt-get download $package left no .deb" >&2; return 1; }
    # Only the image files and the licence texts.
    dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$dir/x" --wildcards "./$inside/$glob" "$@" || {
        echo "sample-images.sh: cannot extract the images of $deb" >&2
        return 1
    }
    rm -rf "$dest.new"
    mkdir -p "$dest.new/licence" || return 1
    find "$dir/x/$inside" -maxdepth 1 -type f -name "$glob" -exec mv -t "$dest.new" {} + || return 1
    local licence
    for licence in "$@"; do
        cp "$dir/x/$licence" "$dest.new/licence/$(basename "$licence")" || return 1
    done
    echo "$version" >"$dest.new/.version" || return 1
    rm -rf "$dest"
    mv "$dest.new" "$dest" || return 1
    rm -rf "$dir"
    echo "$version"
}

# A manifest line: path, package and version, licence, description.
line() {
    printf '%s\t%s\t%s\t%s\n' "$1" "$2" "$3" "$4"
}

manifest="$work/images.tsv"
{
    echo "# Sample photographs fetched by tools/sample-images.sh; read by glare/photos.h."
    echo "# path	package	licence	description"
} >"$manifest"
failed=0

# The OpenEXR sample images (github.com/AcademySoftwareFoundation/openexr-images), as Psychtoolbox ships
# them; debian/copyright: "Files: Psychtoolbox/PsychDemos/OpenEXRImages ... License: BSD-3", the text in
# the folder's Contents.m.
p=psychtoolbox-3-common
if v="$(fetch "$p" usr/share/psychtoolbox-3/PsychDemos/OpenEXRImages '*.exr' \
    ./usr/share/psychtoolbox-3/PsychDemos/OpenEXRImages/Contents.m "./usr/share/doc/$p/copyright")"; then
    while IFS='|' read -r file what; do
        if [ -f "$cache/$p/$file" ]; then
            line "$p/$file" "$p $v" BSD-3-Clause "$what (OpenEXR sample set, (c) 2004 Industrial Light & Magic)"
        fi
    done >>"$manifest" <<'EOF'
CandleGlass.exr|a candle flame beside a wine glass in the dark, 1000x810 RGBA, PIZ scanlines
Desk.exr|an open book on a desk before a sunlit stained-glass window, 644x874 RGBA, PIZ scanlines
GoldenGate.exr|the Golden Gate Bridge and San Francisco's lights at dusk, 1262x860 RGB, PIZ tiles
Ocean.exr|the sun through pine branches over the ocean, 1255x876 RGB, ZIP tiles
StillLife.exr|oil lamps, wine glasses and bread on a table at night, 1240x846 RGBA, PIZ scanlines
WideColorGamut.exr|not a photograph: a synthetic wide-gamut chromaticity triangle, 800x800 RGB, ZIP scanlines
EOF
else
    failed=1
fi

# Blender's studio-light worlds; their license.txt: "All HDRIs are licenses as CC0. These were created
# by Greg Zaal (HDRI Haven https://hdrihaven.com)."
p=blender-data
if v="$(fetch "$p" usr/share/blender/datafiles/studiolights/world '*.exr' \
    ./usr/share/blender/datafiles/studiolights/world/license.txt "./usr/share/doc/$p/copyright")"; then
    for name in city courtyard forest interior night studio sunrise sunset; do
        if [ -f "$cache/$p/$name.exr" ]; then
            line "$p/$name.exr" "$p $v" CC0-1.0 "$name: an equirectangular HDRI by Greg Zaal (HDRI Haven), 1024x512 RGB, DWAB scanlines"
        fi
    done >>"$manifest"
else
    failed=1
fi

mv "$manifest" "$cache/images.tsv"

# What the cache holds now.
echo "sample photographs in $cache (manifest: images.tsv):"
count=0
while IFS=$'\t' read -r path package licence _; do
    case "$path" in "#"* | "") continue ;; esac
    count=$((count + 1))
    printf '  %-42s %6s KB  %-13s %s\n' "$path" "$(($(stat -c %s "$cache/$path") / 1024))" "$licence" "$package"
done <"$cache/images.tsv"
echo "$count pictures, $(du -sh "$cache" | cut -f1) in all; licence texts in each package's licence/ folder"
exit "$failed"
