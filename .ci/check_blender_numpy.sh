#!/usr/bin/env bash
# The Blender scripts (scripts/blender_*.py) with another numpy than Debian's: numpy 2 (as a
# Blender that bundles it has; Debian's 3.4 glTF add-on needs the `numpy.bool` alias, which numpy
# 2 has again and 1.24-1.26 lack) imports and checks the flock and exports the rig template
# byte-identical to the one made on Debian's numpy 1; without numpy the scripts stop with one
# line naming the package to install. Usage: .ci/check_blender_numpy.sh FLOCK.glb FLOCK.csv
set -euo pipefail
cd "$(dirname "$0")/.."
glb="$1"
csv="$2"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
retry() {
    local n
    for n in 1 2 3 4; do
        "$@" && return 0
        echo "attempt $n of: $* failed; retrying in $((n * 10)) s" >&2
        sleep $((n * 10))
    done
    "$@"
}
blend() { blender -b --factory-startup --python-exit-code 1 "$@"; }
# numpy 2 for Blender's own Python version, from PyPI, in a directory of its own.
pyver="$(blend --python-expr 'import sys; print("PYVER %d.%d" % sys.version_info[:2])' 2>/dev/null | sed -n 's/^PYVER //p')"
python3 -m venv "$dir/venv"
retry "$dir/venv/bin/pip" install --quiet --disable-pip-version-check --only-binary=:all: \
    --python-version "$pyver" --target "$dir/np2" "numpy>=2,<3"

blend --python scripts/blender_rig_template.py -- "$glb" "$dir/rig_system.glb" | grep -E '^(EXPORTED|FAILED)'
BLENDER_NUMPY="$dir/np2" blend --python .ci/blender_numpy.py --python scripts/blender_rig_template.py -- \
    "$glb" "$dir/rig_np2.glb" | grep -E '^(NUMPY|EXPORTED|FAILED)'
cmp "$dir/rig_system.glb" "$dir/rig_np2.glb"
echo "rig template: the same file under the system's numpy and numpy 2"
BLENDER_NUMPY="$dir/np2" blend --python .ci/blender_numpy.py --python scripts/blender_import_check.py -- \
    "$glb" - "$csv" | grep -E '^(NUMPY|OBJECTS|POSITIONS|FAILED|OK)'
# Without numpy: exit 1 and the one line naming the fix, not a traceback.
set +e
BLENDER_NUMPY=none blend --python .ci/blender_numpy.py --python scripts/blender_import_check.py -- \
    "$glb" - "$csv" >"$dir/none.out" 2>"$dir/none.err"
rc=$?
set -e
[ "$rc" -ne 0 ] || { echo "FAILED: the import check passed without numpy"; exit 1; }
grep -q "apt install python3-numpy" "$dir/none.err" || { echo "FAILED: no message naming python3-numpy"; cat "$dir/none.err"; exit 1; }
if grep -q "Traceback" "$dir/none.err"; then echo "FAILED: a traceback without numpy"; cat "$dir/none.err"; exit 1; fi
echo "without numpy: exit $rc and: $(grep -m1 'apt install' "$dir/none.err")"
