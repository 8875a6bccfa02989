"""formation: animate bird flocks flying in line formations (V, U, J, echelon).

The Rust library does the work; this package gives it Python habits::

    import formation
    anim = formation.animate("examples_data/barnacle_geese_v.json", birds=14, seconds=10, seed=7)
    anim.positions.shape        # (frames, birds, 3), wingspans, x east, y north, z up
    anim.savings.mean(axis=0)   # each bird's mean saving e
    anim.to_pandas()            # the CSV's columns, one row per frame and bird
    anim.write("flock.glb")     # any format `formation animate -o` writes

Options are the library's option paths (``steady.fps``, ``initiate.max_turn_rate``,
``render.width``...), given as ``**{"steady.fps": 30}`` or per section as
``steady={"fps": 30}``; ``formation.default_options()`` lists them with their defaults.
Bad input raises ``ValueError`` (a file that cannot be read or written: ``OSError``) with the
same one-line message as the command line, naming the option path. Suspicious input (a
formation that opens forward, an implausible scale, a path the flock outflies) is a warning of
class ``formation.FormationWarning`` (Python's ``warnings``: filter it, or turn it into an error
with ``warnings.simplefilter("error", formation.FormationWarning)``); ``strict=True`` makes
``extract`` and ``animate`` raise ``ValueError`` on the first one instead. ``formation.example(NAME)``
gives the path of an example bundled with the package (``formation.examples()`` lists them).
``Params``, ``Animation`` and ``Annotations`` pickle exactly (``multiprocessing``, joblib, Dask).
"""

from __future__ import annotations

import json as _json
import os as _os
from typing import Any as _Any

import re as _re
import warnings as _warnings

import numpy as _np

from . import _native
from ._native import Animation, Annotations, Params

__version__ = _native.__version__

__all__ = [
    "Animation",
    "Annotations",
    "FormationWarning",
    "Params",
    "animate",
    "default_options",
    "example",
    "examples",
    "extract",
    "power",
    "read_animation",
    "read_annotations",
    "solve",
]

class FormationWarning(UserWarning):
    """Suspicious input that still gave a result: a formation that opens forward (the heading or
    the image's y axis probably wrong), an implausible scale, few frames, a path the flock flies
    past. The message says what to give to fix it."""


_EXAMPLES = _os.path.join(_os.path.dirname(__file__), "examples")


def examples() -> list[str]:
    """The names of the examples bundled with the package (``formation.example(NAME)``)."""
    return sorted(n for n in _os.listdir(_EXAMPLES) if n != "README.md" and not n.startswith("."))


def example(name: str) -> str:
    """The path of an example bundled with the package: annotated footage of a real formation
    in each input format the tool reads (``"barnacle_geese_v.json"``, ``"cranes_v_dltdv.csv"``,
    ``"snow_geese_j.csv"``, ``"pelicans_u_labelme"`` (a directory), ...), the same files as
    the repository's ``examples_data/``; their README says where each comes from.

    ``formation.animate(formation.example("barnacle_geese_v.json"))`` runs from any directory.
    Raises ValueError naming the examples there are for an unknown name.
    """
    if not isinstance(name, str) or _os.sep in name or name in ("", ".", ".."):
        raise ValueError(f"example: expected an example's name, got {name!r}; one of {', '.join(examples())}")
    path = _os.path.join(_EXAMPLES, name)
    if not _os.path.exists(path):
        stems = {_os.path.splitext(n)[0]: n for n in examples()}
        if name in stems:
            path = _os.path.join(_EXAMPLES, stems[name])
        else:
            raise ValueError(f"example: no example named {name!r}; there are {', '.join(examples())}")
    return path


# The library's messages name options by their path (``read.heading``); Python gives the read
# options as ``read_annotations``' keywords or an option section.
_READ_KEYS = ("heading", "y_origin", "wingspan_px")


def _python_spelling(message: str, annotations_given: bool) -> str:
    def give(key: str, value: str | None) -> str:
        if value is None:
            return f"read_annotations' {key}=" if annotations_given else f'read={{"{key}": ...}}'
        v = value if _re.fullmatch(r"[-+]?[0-9.]+", value) else f'"{value}"'
        return f"read_annotations(..., {key}={v})" if annotations_given else f'read={{"{key}": {v}}}'

    keys = "|".join(_READ_KEYS)
    message = _re.sub(
        rf"\bread\.({keys}) ([A-Za-z]+|[-+]?[0-9.]+)(?=[\s,;)]|$)",
        lambda m: give(m.group(1), m.group(2)),
        message,
    )
    message = _re.sub(rf"\bread\.({keys})\b", lambda m: give(m.group(1), None), message)
    return message


def _warn(messages: list[str], strict: bool, annotations_given: bool) -> None:
    """Raises the run's warnings as ``FormationWarning`` (``strict``: the first as ValueError)."""
    messages = [_python_spelling(m, annotations_given) for m in messages]
    if strict and messages:
        more = len(messages) - 1
        tail = "" if more == 0 else f" (and {more} more warning{'s' if more > 1 else ''})"
        raise ValueError(f"strict: {messages[0]}{tail}")
    for m in messages:
        _warnings.warn(m, FormationWarning, stacklevel=3)


_HEADINGS = {"up": "Up", "right": "Right", "down": "Down", "left": "Left"}


def _json_default(v: _Any) -> _Any:
    if isinstance(v, _os.PathLike):
        return _os.fspath(v)
    if isinstance(v, _np.generic):
        return v.item()
    if isinstance(v, _np.ndarray):
        return v.tolist()
    raise TypeError(f"{type(v).__name__} is not an option value")


def _pairs(options: dict[str, _Any], prefix: str = "") -> list[tuple[str, str]]:
    """(option path, JSON text) pairs; a name may be dotted or a whole section (a dict)."""
    out = []
    for name, value in options.items():
        if prefix and name.startswith(prefix):
            name = name[len(prefix) :]
        # The heading as read_annotations takes it ("down", degrees), in an option too.
        if prefix + name == "read.heading" and isinstance(value, (str, int, float)):
            out.append((name, _heading(value)))
            continue
        if prefix + name == "read" and isinstance(value, dict) and isinstance(value.get("heading"), (str, int, float)):
            value = {**value, "heading": _json.loads(_heading(value["heading"]))}
        try:
            text = _json.dumps(value, default=_json_default, allow_nan=True)
        except TypeError as e:
            raise ValueError(f"{prefix}{name}: {e}") from None
        out.append((name, text))
    return out


def _heading(h: _Any) -> str:
    if isinstance(h, str):
        word = _HEADINGS.get(h.lower())
        if word is None:
            raise ValueError(f"read.heading: `{h}` is not a heading; use up, right, down, left or degrees")
        return _json.dumps(word)
    return _json.dumps({"Degrees": float(h)})


def default_options() -> dict:
    """Every option of a run with its default value, as a nested dict (section → option → value).

    The dotted paths into this dict (``steady.fps``) are the names ``animate`` and ``extract``
    accept.
    """
    return _json.loads(_native.default_options())


def read_annotations(
    source: str | _os.PathLike | list,
    *,
    heading: str | float | None = None,
    wingspan_px: float | None = None,
    y_origin: str | None = None,
    name: str = "points",
) -> Annotations:
    """Annotated frames of a flock, from a file or from points in memory.

    ``source`` is a file or directory in any input format the command line reads (native JSON,
    long CSV ``frame,bird,x,y``, DLTdv CSV, Labelme JSON or a directory of them), or a list of
    frames, each an array-like of shape (birds, 2) of image pixels.

    ``heading`` (the flock's flight direction in the image: ``"up"``, ``"right"``, ``"down"``,
    ``"left"`` or degrees clockwise from image-up), ``wingspan_px`` (one wingspan in pixels) and
    ``y_origin`` (``"top"`` or ``"bottom"``, CSV only) override what the file says (the
    ``read.*`` options). For points, ``heading`` defaults to up, ``wingspan_px`` is required and
    ``name`` is the source's name.

    Raises ValueError for malformed input (naming the file, frame and bird) and OSError for a
    file that cannot be read.
    """
    if isinstance(source, (str, _os.PathLike)):
        options: list[tuple[str, str]] = []
        if heading is not None:
            options.append(("heading", _heading(heading)))
        if wingspan_px is not None:
            options.append(("wingspan_px", _json.dumps(float(wingspan_px))))
        if y_origin is not None:
            options.append(("y_origin", _json.dumps(y_origin)))
        return _native.read_annotations(_os.fspath(source), options)
    if wingspan_px is None:
        raise ValueError("read.wingspan_px: points in memory need the wingspan in pixels")
    if y_origin is not None:
        raise ValueError("read.y_origin: only for CSV files; points are image pixels, y down")
    frames = []
    for k, f in enumerate(source):
        a = _np.asarray(f, dtype=_np.float64)
        if a.ndim != 2 or a.shape[1] != 2:
            raise ValueError(f"frame {k}: expected an array of shape (birds, 2), got {a.shape}")
        frames.append(_np.ascontiguousarray(a).ravel())
    return _native.annotations_from_points(
        name, _heading("up" if heading is None else heading), float(wingspan_px), frames
    )


def extract(
    annotations: Annotations | str | _os.PathLike,
    *,
    seed: int = 0,
    strict: bool = False,
    **options: _Any,
) -> Params:
    """Formation parameters of annotated footage (RANSAC over every frame).

    ``annotations`` is an ``Annotations`` object or a path (annotations in any format, or a
    params file, which is read and checked). ``options`` are option paths of the ``extract``
    and ``read`` sections (``**{"extract.iterations": 2000}`` or ``extract={...}``). The same
    seed gives the same parameters as ``formation extract --seed``.

    Returns ``Params``: ``.birds``, ``.frames`` (one dict per frame), ``.summary``,
    ``.to_dict()``, ``.to_json()``. Raises ValueError for bad input or options.

    Suspicious input (``.summary["warnings"]``) is also raised as ``FormationWarning``s;
    ``strict=True`` raises ValueError on the first instead.
    """
    given = isinstance(annotations, Annotations)
    if isinstance(annotations, _os.PathLike):
        annotations = _os.fspath(annotations)
    params = _native.extract(annotations, [("seed", str(int(seed)))] + _pairs(options))
    summary = params.summary or {}
    _warn([w["message"] for w in summary.get("warnings", [])], strict, given)
    return params


def animate(
    input: Annotations | Params | str | _os.PathLike,
    birds: int = 14,
    seconds: float | None = None,
    seed: int = 0,
    path: str | _os.PathLike | None = None,
    initiation: bool = True,
    progress: _Any = False,
    land: bool = False,
    land_on: str | None = None,
    strict: bool = False,
    **options: _Any,
) -> Animation:
    """The whole pipeline: extraction, steady flight, take-off, wingbeats, savings.

    ``input``: annotations (an ``Annotations`` object or a file in any input format), or
    formation parameters (a ``Params`` object or a params file). ``birds``: flock size.
    ``seconds``: length of the steady flight (None: the library's default, 20 s). ``seed``:
    equal seeds and inputs give identical motion, the same as ``formation animate --seed``.
    ``path``: a JSON or CSV file of the leader's path (the ``course.path`` option).
    ``initiation``: fly the take-off first (False: the steady flight alone). ``land``: end
    with a landing stage (glide, flare, touch-down, rest; at the path's end with ``path``), the
    same as ``formation animate --land``; ``land_on``: ``"ground"`` (the default) or
    ``"water"`` (implies ``land``; the ``landing.surface`` option). ``progress``:
    False (the default) shows nothing; True shows a progress bar: the command line's on a
    terminal, elsewhere (a notebook) a tqdm bar per stage when tqdm is installed, else one
    line on ``sys.stderr`` rewritten in place; a callable is called as
    ``progress(stage, done, total)`` at the start of each stage, at most ten times a second
    while it runs and at its end (an exception it raises ends the run and is raised here).

    ``strict``: raise ValueError on the first warning instead of a ``FormationWarning``
    (the command line's ``--strict``).

    ``options``: any other option by its path in the library's configuration, dotted
    (``**{"steady.fps": 30, "initiate.max_turn_rate": 1.2}``) or per section
    (``steady={"fps": 30}``); ``formation.default_options()`` lists them all. ``render.*``
    options are kept for ``Animation.write``.

    Returns an ``Animation`` whose arrays (float64) are ``positions`` (frames × birds × 3),
    ``headings``, ``banks``, ``pitches``, ``wing_phase``, ``speeds``, ``savings`` and ``xi``
    (frames × birds) and ``times`` (frames); ``to_pandas()`` and ``write(path)`` give the CSV
    table and every output format. The GIL is released while it runs.

    Raises ValueError (with the command line's one-line message, naming the option path, file,
    frame or bird) for bad input, OSError for unreadable files.
    """
    if isinstance(birds, bool) or not isinstance(birds, (int, _np.integer)):
        raise ValueError(f"steady.birds: expected a whole number of birds, got {birds!r}")
    pairs = [
        ("seed", _json.dumps(int(seed))),
        ("initiation", _json.dumps(bool(initiation))),
        ("steady.birds", _json.dumps(int(birds))),
    ]
    if seconds is not None:
        pairs.append(("seconds", _json.dumps(float(seconds))))
    if path is not None:
        pairs.append(("course.path", _json.dumps(_os.fspath(path))))
    if land or land_on is not None:
        pairs.append(("land", _json.dumps(True)))
    if land_on is not None:
        if not isinstance(land_on, str):
            raise ValueError(f"landing.surface: expected 'ground' or 'water', got {land_on!r}")
        pairs.append(("landing.surface", _json.dumps(land_on)))
    given = isinstance(input, Annotations)
    if isinstance(input, _os.PathLike):
        input = _os.fspath(input)
    if callable(progress):
        anim, warned = _native.animate(input, pairs + _pairs(options), False, progress)
    elif progress and not _stderr_is_terminal():
        bar = _StageBar()
        try:
            anim, warned = _native.animate(input, pairs + _pairs(options), False, bar)
        finally:
            bar.close()
    else:
        anim, warned = _native.animate(input, pairs + _pairs(options), bool(progress))
    _warn(warned, strict, given)
    return anim


def _stderr_is_terminal() -> bool:
    import sys

    try:
        return sys.stderr is not None and sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


class _StageBar:
    """``animate(progress=True)`` away from a terminal: a tqdm bar per stage (``tqdm.auto``,
    a widget in Jupyter) when tqdm is installed, else one line on ``sys.stderr`` rewritten
    with a carriage return."""

    def __init__(self):
        try:
            from tqdm.auto import tqdm
        except ImportError:
            tqdm = None
        self._tqdm = tqdm
        self._bar = None
        self._stage = None

    def __call__(self, stage: str, done: int, total: int) -> None:
        if stage != self._stage:
            self.close()
            self._stage = stage
            if self._tqdm is not None:
                self._bar = self._tqdm(total=total, desc=stage, leave=False)
        if self._bar is not None:
            self._bar.update(done - self._bar.n)
        else:
            import sys

            width = 30
            filled = width * done // total if total else width
            sys.stderr.write(f"\r{stage:>12} [{'=' * filled}{' ' * (width - filled)}] {done}/{total}")
            sys.stderr.flush()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self._stage is not None and self._tqdm is None:
            import sys

            sys.stderr.write("\n")
            sys.stderr.flush()
        self._stage = None


def read_animation(path: str | _os.PathLike) -> Animation:
    """An animation JSON file written by ``formation animate -o flock.json`` (or by
    ``Animation.write``), as an ``Animation``."""
    return _native.read_animation(_os.fspath(path))


def power(x, y, z=None, core_radius: float | None = None, **options: _Any):
    """Hummel's power reduction of a shape: ``(e, xi, E)``.

    ``x`` (lateral, right of the flight direction) and ``y`` (distance behind the leader) are
    array-likes of wingspans, one value per bird. ``e[i]`` is bird i's saving (the fraction of
    its solo induced power the others save it), ``xi = e / E`` and ``E = e.sum()``.
    ``z`` (heights, wingspans, up) selects the 3-D wake: each pair of birds at its own vertical
    distance (the option ``wake`` is then ``"3d"`` unless given; ``wake="planar"`` ignores the
    heights, as the command line's ``--wake planar`` does). ``core_radius`` is the vortex core
    radius in wingspans (the ``aero.core_radius`` option); ``options`` are other options of the
    aerodynamic model by name (``wake``, ``wake_descent``, ...).

    Raises ValueError naming the birds when two birds' wings overlap, or for non-finite
    values, a ``z`` of another length than ``x``, or fewer than two birds.
    """
    x = _np.asarray(x, dtype=_np.float64).ravel()
    y = _np.asarray(y, dtype=_np.float64).ravel()
    zs = None
    if z is not None:
        z = _np.asarray(z, dtype=_np.float64).ravel()
        if z.shape != x.shape:
            raise ValueError(f"z: {z.size} values for {x.size} birds in x")
        zs = z.tolist()
        if "wake" not in options and "aero.wake" not in options:
            options = {**options, "wake": "3d"}
    if core_radius is not None:
        options = {"core_radius": core_radius, **options}
    return _native.power(x.tolist(), y.tolist(), zs, _pairs(options, "aero."))


def solve(x, xi, y=None, *, tolerance: float | None = None, patience: int | None = None,
          core_radius: float | None = None) -> dict:
    """Longitudinal positions y that give the birds at lateral positions ``x`` the relative
    savings ``xi`` (renormalised to sum to 1), by Newton's method on Hummel's model.

    ``y``: a start (else the library's own starts). ``tolerance``: converged means
    ‖ξ − ξ̂‖₂ ≤ tolerance (default 1e-9); ``patience``: Newton steps per attempt.

    Returns a dict: ``y`` (front-most bird at 0), ``xi`` achieved, ``target``, ``residual``,
    ``converged`` (not converging is not an error), ``total`` (E), ``evaluations``,
    ``termination``. Raises ValueError for unreachable targets (naming the birds), collisions
    and bad input. The GIL is released while it runs.
    """
    x = _np.asarray(x, dtype=_np.float64).ravel().tolist()
    xi = _np.asarray(xi, dtype=_np.float64).ravel().tolist()
    if y is not None:
        y = _np.asarray(y, dtype=_np.float64).ravel().tolist()
    aero = [] if core_radius is None else [("core_radius", _json.dumps(float(core_radius)))]
    return _native.solve(x, xi, y, tolerance, patience, aero)


# ``from __future__ import annotations`` binds the name ``annotations``: not part of the API.
del annotations


def _unpickle(kind: str, state: bytes):
    """Rebuilds a pickled ``Params``, ``Animation`` or ``Annotations`` (what their
    ``__reduce__`` names); the state is their exact native form."""
    return _native.from_state(kind, state)
