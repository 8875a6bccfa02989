#!/usr/bin/env bash
# Regenerates the pictures in README.md, docs/usage.md, docs/export.md and docs/initiation.md from the bundled example
# data with the release binary, and prints the size of the README job's GIF (to keep the numbers
# in README.md and docs/export.md honest). Usage: bash scripts/readme_images.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
B=target/release/formation
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
E=examples_data
I=docs/images
mkdir -p "$I"
$B extract $E/barnacle_geese_v.json -o "$T/geese.json" > /dev/null
$B plot shape "$T/geese.json" --frame 0 -o "$I/usage-fit.png"
# The README job's animation: take-off and steady frames from the follow camera.
$B animate "$T/geese.json" --birds 14 -o "$T/flock.json" -o "$T/frames/" --picture-fps 1 --quiet
n=$(ls "$T/frames" | wc -l)
echo "$n frames at 1 fps"
cp "$T/frames/frame_00002.png" "$I/usage-initiation.png"
# docs/initiation.md: the README job's ground take-off, two frames (2 s and 6 s) and its paths.
cp "$T/frames/frame_00002.png" docs/takeoff-ground-2s.png
cp "$T/frames/frame_00006.png" docs/takeoff-ground-6s.png
$B plot paths "$T/flock.json" -o docs/takeoff-paths.png
last=$(ls "$T/frames" | tail -n 3 | head -n 1)
cp "$T/frames/$last" "$I/usage-steady.png"
# The ground observer: the flock passes over at 70 % of the film; show it a second before.
$B render "$T/flock.json" -o "$T/ground/" --camera ground --picture-fps 1 --sun --quiet
g=$(( (n - 1) * 7 / 10 - 1 ))
cp "$T/ground/$(printf 'frame_%05d.png' "$g")" "$I/usage-ground.png"
# One close frame per species (a small flock, so the follow camera is at its closest).
for sp in goose crane pelican; do
  $B animate "$T/geese.json" --birds 4 --seconds 6 --species "$sp" --seed 3 \
    -o "$T/$sp/" --picture-fps 2 --quiet
  # Frame 45 (22.5 s) when the flight is that long, else 3 s before its end.
  f="$T/$sp/frame_00045.png"
  [ -f "$f" ] || f="$T/$sp/$(ls "$T/$sp" | tail -n 7 | head -n 1)"
  cp "$f" "$I/species-$sp.png"
done
# The README job's GIF, for its size.
$B animate $E/barnacle_geese_v.json --birds 14 -o "$T/flock.gif" --quiet
echo "README job GIF: $(stat -c %s "$T/flock.gif") bytes"
$B plot paths "$T/flock.json" -o "$I/usage-paths.png"
$B plot xi "$T/flock.json" -o "$I/usage-xi.png"
$B plot power "$T/flock.json" --key 2 -o "$I/usage-power.png"
$B plot savings "$T/flock.json" -o "$I/usage-savings.png"
$B plot wingbeat --species goose -o "$I/usage-wingbeat.png"
# Large flocks (docs/large-flocks.md): 200 geese at 1280x720, 1000 at 1920x1080, seed 0.
$B animate $E/barnacle_geese_v.json --birds 200 --skein-layout grid -o "$T/sky200.json" --quiet
$B render "$T/sky200.json" -o "$T/sky200/" --size 1280x720 --picture-fps 1 --quiet
cp "$T/sky200/frame_00025.png" "$I/skeins-200.png"
$B animate $E/barnacle_geese_v.json --birds 1000 --skein-layout grid -o "$T/sky1000.json" --quiet
$B render "$T/sky1000.json" -o "$T/sky1000/" --size 1920x1080 --picture-fps 1 --quiet
cp "$T/sky1000/frame_00028.png" "$I/skeins-1000.png"
cp "$T/sky1000/frame_00005.png" "$I/skeins-1000-takeoff.png"
# The natural and grid layouts side by side: 1000 geese, 10 s of steady flight, at 8 s.
for L in natural grid; do
  $B animate $E/barnacle_geese_v.json --birds 1000 --no-initiation --seconds 10 \
    --skein-layout $L -o "$T/layout-$L.json" --quiet
  $B render "$T/layout-$L.json" -o "$T/layout-$L/" --size 1920x1080 --picture-fps 1 --quiet
  cp "$T/layout-$L/frame_00008.png" "$I/skeins-1000-$L.png"
done
echo "pictures written to $I"
