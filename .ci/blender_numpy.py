# Run by Blender before a script (`blender -b --python .ci/blender_numpy.py --python SCRIPT`):
# makes Blender's Python see another numpy than the system's, as on a Blender that bundles its
# own. BLENDER_NUMPY=none hides numpy altogether; BLENDER_NUMPY=DIR imports numpy from DIR only
# (a `pip install --target DIR numpy` tree), first, as a Blender whose add-ons loaded it would.
import importlib.machinery
import os
import sys

where = os.environ["BLENDER_NUMPY"]
for m in [m for m in sys.modules if m == "numpy" or m.startswith("numpy.")]:
    del sys.modules[m]


class OtherNumpy:
    def find_spec(self, name, path=None, target=None):
        if name != "numpy" and not name.startswith("numpy."):
            return None
        if where == "none":
            raise ImportError(f"No module named {name!r} (hidden by .ci/blender_numpy.py)")
        if name == "numpy":
            return importlib.machinery.PathFinder.find_spec(name, [where])
        return None


sys.meta_path.insert(0, OtherNumpy())
if where != "none":
    import numpy

    print("NUMPY", numpy.__version__, numpy.__file__)
else:
    print("NUMPY none")
