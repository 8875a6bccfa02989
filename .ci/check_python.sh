#!/usr/bin/env bash
# The Python package: a fresh virtual environment, the wheel built by maturin and installed
# (reusing this checkout's target/ so the library's release build is not repeated), its pytest
# suite (round trips against the binary) and the example script. Needs target/release/formation.
set -euo pipefail
cd "$(dirname "$0")/.."
retry() {
    local n
    for n in 1 2 3 4; do
        "$@" && return 0
        echo "attempt $n of: $* failed; retrying in $((n * 10)) s" >&2
        sleep $((n * 10))
    done
    "$@"
}
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
if ! python3 -m venv "$dir/venv"; then
    export DEBIAN_FRONTEND=noninteractive
    retry apt-get update -qq >/dev/null
    retry apt-get install -y -qq python3-venv >/dev/null
    python3 -m venv "$dir/venv"
fi
py="$dir/venv/bin/python"
# maturin (and the package's `formation` command) from the venv.
export PATH="$dir/venv/bin:$PATH"
retry "$py" -m pip install --quiet --disable-pip-version-check maturin pytest numpy pandas matplotlib
# Dask for the sweep test (python/tests/test_dask.py), required here rather than skipped.
retry "$py" -m pip install --quiet --disable-pip-version-check "dask==2026.8.0" "distributed==2026.8.0"
export FORMATION_REQUIRE_DASK=1
# The documented `pip install ./python`, without build isolation (maturin is installed above).
CARGO_TARGET_DIR="$PWD/target" retry "$py" -m pip install --quiet --disable-pip-version-check \
    --no-build-isolation ./python
# Captured first: grep -q stops reading at the first match, and under pipefail the writer's
# broken pipe would fail the step.
help_text="$("$py" -c "import formation; help(formation.animate)")"
grep -q "steady.fps" <<<"$help_text"
FORMATION_BIN="$PWD/target/release/formation" "$py" -m pytest -q -p no:cacheprovider python/tests
"$py" examples/python/flock_savings.py --out "$dir/example"
for f in savings.png savings_tidy.csv savings_per_bird.csv; do
    [ -s "$dir/example/$f" ] || { echo "the example wrote no $f"; exit 1; }
done
magic="$(head -c 8 "$dir/example/savings.png" | od -An -c)"
grep -q 'P   N   G' <<<"$magic" || { echo "savings.png is not a PNG"; exit 1; }
