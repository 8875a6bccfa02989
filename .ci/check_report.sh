#!/usr/bin/env bash
# `formation report` in headless Chromium: the page of annotations, of a params file
# and of an animation must load without a console message (an error, a failed request: the page
# is self-contained) and draw every chart it declares (`data-charts` = `data-charts-rendered`,
# counted by the page's own script from the SVGs' boxes). With --screenshots DIR, also writes the
# screenshots used in docs/formats.md.
set -euo pipefail
f=${FORMATION:-./target/release/formation}
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
shots=""
if [ "${1:-}" = "--screenshots" ]; then shots="$2"; fi
browser=$(command -v chromium-headless-shell || command -v chromium || true)
[ -n "$browser" ] || { echo "no headless Chromium (apt-get install chromium-headless-shell)"; exit 1; }
$f animate examples_data/barnacle_geese_v.json --birds 14 --seconds 8 --quiet -o "$dir/flock.json"
$f extract examples_data/barnacle_geese_v.json --wingspan-m 1.4 -o "$dir/geese.json" >/dev/null
$f report examples_data/pelicans_u_labelme --quiet -o "$dir/annotations.html"
$f report "$dir/geese.json" --quiet -o "$dir/params.html"
$f report "$dir/flock.json" --quiet -o "$dir/animation.html"
for page in annotations params animation; do
    html="$dir/$page.html"
    if grep -Eq '(src|href)="(https?:)?//' "$html"; then echo "$page: fetches from the network"; exit 1; fi
    dom=$("$browser" --headless --no-sandbox --disable-gpu --enable-logging=stderr --v=0 \
        --virtual-time-budget=5000 --dump-dom "file://$html" 2>"$dir/$page.log")
    if grep -q ':CONSOLE' "$dir/$page.log"; then
        echo "$page: console messages:"; grep ':CONSOLE' "$dir/$page.log"; exit 1
    fi
    want=$(grep -o 'data-charts="[0-9]*"' <<<"$dom" | head -n 1 | tr -dc 0-9)
    got=$(grep -o 'data-charts-rendered="[0-9]*"' <<<"$dom" | head -n 1 | tr -dc 0-9)
    echo "$page.html: $got of $want charts rendered, no console messages"
    [ -n "$want" ] && [ "$want" -gt 0 ] && [ "$got" = "$want" ] || { echo "$page: missing charts"; exit 1; }
    if [ -n "$shots" ]; then
        "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1280,1800 \
            --screenshot="$shots/report-$page.png" "file://$html" 2>/dev/null
    fi
done
