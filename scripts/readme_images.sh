#!/usr/bin/env bash
# Regenerates the pictures in README.md and docs/usage.md from the bundled example data with the
# release binary. Usage: bash scripts/readme_images.sh
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
$B animate "$T/geese.json" --birds 14 -o "$T/flock.json" -o "$T/frames/" --picture-fps 1 --quiet
ls "$T/frames" | wc -l
cp "$T/frames/frame_00003.png" "$I/usage-initiation.png"
last=$(ls "$T/frames" | tail -n 3 | head -n 1)
cp "$T/frames/$last" "$I/usage-steady.png"
$B plot paths "$T/flock.json" -o "$I/usage-paths.png"
$B plot xi "$T/flock.json" -o "$I/usage-xi.png"
$B plot power "$T/flock.json" --key 2 -o "$I/usage-power.png"
$B plot wingbeat --species goose -o "$I/usage-wingbeat.png"
echo "pictures written to $I"
