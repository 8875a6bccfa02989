#!/usr/bin/env bash
# The key-shape solve against scipy's MINPACK LM (least_squares(method="lm"), solver only) on the
# same problems, in one run:
#   bash benches/compare_solve.sh            # N = 40, 200, 1000 for both, 10 000 for formation
#   SIZES=40,200 bash benches/compare_solve.sh
# 1. `cargo bench --bench solve` (criterion: `keyshape::solve` alone) for SIZES;
# 2. the whole process, `formation solve tN.json -o sN.json --quiet` under bash's `time`, on the
#    same targets and start written by benches/solve_scipy.py (sizes up to 1000);
# 3. scipy's solver alone (benches/solve_scipy.py) for the sizes up to 1000 (its dense QR grows
#    like N³: about a minute at 1000).
# Needs python3 with numpy and scipy (pip install numpy scipy).
set -euo pipefail
cd "$(dirname "$0")/.."
SIZES=${SIZES:-40,200,1000,10000}
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB, load $(cut -d' ' -f1-3 /proc/loadavg)"
SOLVE_SIZES=$SIZES cargo bench --bench solve -- --warm-up-time 1 --measurement-time 3 2>&1 | grep -E "^solve|time:|N = "
SMALL=$(echo "$SIZES" | tr ',' '\n' | awk '$1 <= 1000' | tr '\n' ' ')
cargo build --release --quiet
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
python3 benches/solve_scipy.py --write-targets "$DIR" $SMALL
for n in $SMALL; do
    for run in 1 2 3 4 5; do
        TIMEFORMAT="formation solve (whole process) N=$n run $run: %3R s wall, %3U s user"
        time target/release/formation solve "$DIR/t$n.json" -o "$DIR/s$n.json" --quiet
    done
done
env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE python3 benches/solve_scipy.py $SMALL
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
