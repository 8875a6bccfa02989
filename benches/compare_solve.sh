#!/usr/bin/env bash
# The key-shape solve against scipy's MINPACK LM (least_squares(method="lm"), solver only) on the
# same problems, in one run:
#   bash benches/compare_solve.sh                 # N = 40, 200, 1000, 10 000
#   SIZES=40,200 bash benches/compare_solve.sh
#   SCIPY_MAX=2000 bash benches/compare_solve.sh  # largest N given to scipy (default 2000)
# 1. `cargo bench --bench solve` (criterion: `keyshape::solve` alone, perturbed start) for SIZES;
# 2. the whole process, `formation solve tN.json -o sN.json --quiet` under bash's `time`, five
#    runs per size, on the targets and start written by benches/solve_scipy.py (every size);
# 3. scipy's solver alone (benches/solve_scipy.py) for the sizes up to SCIPY_MAX: its dense QR of
#    the N × (N − 1) Jacobian grows like N³ per iteration (about 6 s at 1000 birds, about a minute
#    at 2000 under load; at 10 000 it would need 0.8 GB per Jacobian and about 10³ times the work
#    of 1000 birds, hours: not run).
# Needs python3 with numpy and scipy (pip install numpy scipy).
set -euo pipefail
cd "$(dirname "$0")/.."
SIZES=${SIZES:-40,200,1000,10000}
SCIPY_MAX=${SCIPY_MAX:-2000}
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB, load $(cut -d' ' -f1-3 /proc/loadavg)"
SOLVE_SIZES=$SIZES cargo bench --bench solve -- --warm-up-time 1 --measurement-time 5 --sample-size 10 perturbed 2>&1 | grep -E "^solve|time:|N = "
ALL=$(echo "$SIZES" | tr ',' ' ')
SCIPY=$(echo "$SIZES" | tr ',' '\n' | awk -v m="$SCIPY_MAX" '$1 <= m' | tr '\n' ' ')
cargo build --release --quiet
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
python3 benches/solve_scipy.py --write-targets "$DIR" $ALL
echo "load before the whole-process runs: $(cut -d' ' -f1-3 /proc/loadavg)"
for n in $ALL; do
    for run in 1 2 3 4 5; do
        TIMEFORMAT="formation solve (whole process) N=$n run $run: %3R s wall, %3U s user"
        time target/release/formation solve "$DIR/t$n.json" -o "$DIR/s$n.json" --quiet
    done
done
echo "load before scipy: $(cut -d' ' -f1-3 /proc/loadavg)"
if [ -n "$SCIPY" ]; then
    env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE python3 benches/solve_scipy.py $SCIPY
fi
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
