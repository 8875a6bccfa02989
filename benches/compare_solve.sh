#!/usr/bin/env bash
# The key-shape solve against scipy's MINPACK LM (least_squares(method="lm"), solver only) on the
# same problems, in one run:
#   bash benches/compare_solve.sh            # N = 40, 200, 1000 for both, 10 000 for formation
#   SIZES=40,200 bash benches/compare_solve.sh
# needs python3 with numpy and scipy (pip install numpy scipy). scipy is not run beyond 1000 birds
# (6 s there already; its dense QR grows like N³).
set -euo pipefail
cd "$(dirname "$0")/.."
SIZES=${SIZES:-40,200,1000,10000}
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB, load $(cut -d' ' -f1-3 /proc/loadavg)"
SOLVE_SIZES=$SIZES cargo bench --bench solve -- --warm-up-time 1 --measurement-time 3 2>&1 | grep -E "^solve|time:|N = "
SCIPY_SIZES=$(echo "$SIZES" | tr ',' '\n' | awk '$1 <= 1000' | tr '\n' ' ')
env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE python3 benches/solve_scipy.py $SCIPY_SIZES
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
