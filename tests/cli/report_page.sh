#!/usr/bin/env bash
# The demo's report as a person sees it: headless Chromium opens DIR/index.html and the page must
# render with no console error, every image loaded (natural width > 0), every section present and
# its plots drawn. A harness page (written here, never part of the report, which has no scripts)
# loads the report in a frame and reads its DOM; Chromium also writes DIR/screenshot.png.
# Usage: report_page.sh DIR
set -u
dir="$(cd "$1" && pwd)" || { echo "FAIL: no report folder $1"; exit 1; }
[ -s "$dir/index.html" ] || { echo "FAIL: $dir/index.html is missing"; exit 1; }
browser="$(command -v chromium || command -v chromium-browser || true)"
[ -n "$browser" ] || { echo "FAIL: no chromium (bash .ci/setup --tests installs it)"; exit 1; }
work="$(mktemp -d)"
trap 'rm -rf "$work"; rm -f "$dir/_page_check.html"' EXIT
cat >"$dir/_page_check.html" <<'HTML'
<!DOCTYPE html><html><body><pre id="out">NOT LOADED</pre>
<iframe id="f" src="index.html" style="width:1400px;height:3000px"></iframe>
<script>
document.getElementById('f').onload = function () {
  var d = this.contentDocument, r = [], broken = 0;
  if (!d) { document.getElementById('out').textContent = 'NO ACCESS'; return; }
  for (var i = 0; i < d.images.length; i++) {
    var im = d.images[i];
    if (!im.complete || im.naturalWidth === 0) { broken++; r.push('BROKEN ' + im.getAttribute('src')); }
  }
  ['techniques', 'fits', 'agreement', 'bench', 'stress', 'debug', 'photos'].forEach(function (id) {
    var s = d.getElementById(id);
    if (!s) r.push('MISSING ' + id);
    else if (s.textContent.trim().length < 40) r.push('EMPTY ' + id);
  });
  r.push('IMAGES ' + d.images.length + ' BROKEN ' + broken);
  r.push('SVG ' + d.getElementsByTagName('svg').length);
  document.getElementById('out').textContent = r.join('\n');
};
</script></body></html>
HTML
flags=(--headless --no-sandbox --disable-gpu --hide-scrollbars --allow-file-access-from-files --no-first-run)
timeout 120 "$browser" "${flags[@]}" --enable-logging=stderr --v=0 --virtual-time-budget=20000 \
    --dump-dom "file://$dir/_page_check.html" 2>"$work/log" |
    sed -n '/<pre id="out">/,/<\/pre>/p' >"$work/dom"
timeout 120 "$browser" "${flags[@]}" --window-size=1400,2600 --screenshot="$dir/screenshot.png" \
    "file://$dir/index.html" >/dev/null 2>&1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
grep -q "IMAGES [1-9][0-9]* BROKEN 0" "$work/dom" || fail "images: $(grep -E 'IMAGES|BROKEN|NOT LOADED|NO ACCESS' "$work/dom" | head -5)"
grep -qE "MISSING|EMPTY" "$work/dom" && fail "sections: $(grep -E 'MISSING|EMPTY' "$work/dom")"
grep -qE "SVG [1-9]" "$work/dom" || fail "no SVG plot drawn"
# Console messages of the report itself (the harness logs none).
if grep -E "CONSOLE" "$work/log" | grep -v "_page_check.html" | grep -q .; then
    fail "console: $(grep -E "CONSOLE" "$work/log" | head -3)"
fi
[ -s "$dir/screenshot.png" ] || fail "no screenshot"
if [ "$failures" = 0 ]; then
    echo "report page: $(grep -oE 'IMAGES [0-9]+' "$work/dom" | head -1), $(grep -oE 'SVG [0-9]+' "$work/dom" | head -1), seven sections, no console message; screenshot $dir/screenshot.png"
fi
exit $((failures > 0))
