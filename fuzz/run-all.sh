#!/usr/bin/env bash
# Runs every fuzz target in turn (one at a time: the machine is shared), SECONDS_PER_TARGET each
# (default 600), with the limits of docs/reliability.md. New corpus entries go to
# fuzz/work/<target> (ignored by git); the committed seeds in fuzz/corpus/<target> are only read.
# Logs: fuzz/work/<target>.log. Builds all targets once first (FUZZ_NO_BUILD=1 skips it), then runs
# the built binaries directly, so a source change mid-run does not trigger rebuilds.
# Needs cargo-fuzz (`cargo install cargo-fuzz --locked`); on stable Rust, RUSTC_BOOTSTRAP=1.
set -uo pipefail
cd "$(dirname "$0")"
secs="${SECONDS_PER_TARGET:-600}"
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(native_json long_csv dltdv_csv labelme_json params animation animation_frames shape target path bird_model sleap_csv dlc_csv mot_txt idtracker_csv trex_npz sleap_h5 pages)
fi
export RUSTC_BOOTSTRAP=1
if [ -z "${FUZZ_NO_BUILD:-}" ]; then
    cargo fuzz build -s none -a || exit 1
fi
bin_dir="target/$(rustc -vV | sed -n 's/^host: //p')/release"
mkdir -p work artifacts
for t in "${targets[@]}"; do
    mkdir -p "work/$t" "artifacts/$t"
    echo "== $t ($secs s) $(date -u +%H:%M:%S)"
    "$bin_dir/$t" "work/$t" "corpus/$t" \
        -artifact_prefix="artifacts/$t/" -max_total_time="$secs" -rss_limit_mb=2048 \
        -timeout=10 -print_final_stats=1 >"work/$t.log" 2>&1
    echo "   exit $? $(date -u +%H:%M:%S); $(grep -E 'stat::number_of_executed_units|Done [0-9]+ runs' "work/$t.log" | tr '\n' ' ')"
done
