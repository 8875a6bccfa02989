#!/usr/bin/env bash
# The key-shape solve against scipy's MINPACK LM on the same problems, in one run:
#   bash benches/compare_solve.sh
# needs python3 with numpy and scipy (pip install numpy scipy).
set -euo pipefail
cd "$(dirname "$0")/.."
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB, load $(cut -d' ' -f1-3 /proc/loadavg)"
cargo bench --bench solve -- --warm-up-time 1 --measurement-time 3 2>&1 | grep -E "^solve|time:|N = "
env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE python3 benches/solve_scipy.py
