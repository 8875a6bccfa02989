"""The Python package against the command line: same seed, same motion; numpy shapes and
dtypes; the CLI's messages as exceptions; the CSV's columns; the GIL released while animating.

Run from the repository root after installing the package: `python -m pytest python/tests`.
The command line compared against is `FORMATION_BIN` (default: target/release/formation).
"""

import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import formation

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples_data" / "barnacle_geese_v.json"
BIN = Path(os.environ.get("FORMATION_BIN", ROOT / "target" / "release" / "formation"))


def cli(*args, check=True):
    if not BIN.exists():
        pytest.skip(f"{BIN} not built (cargo build --release)")
    return subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True, check=check)


@pytest.fixture(scope="module")
def anim():
    return formation.animate(EXAMPLE, birds=9, seconds=4, seed=3)


def test_round_trip_against_the_cli(tmp_path, anim):
    out = tmp_path / "cli.json"
    cli("animate", EXAMPLE, "--birds", 9, "--seconds", 4, "--seed", 3, "--quiet", "-o", out)
    doc = json.loads(out.read_text())
    frames = doc["frames"]
    assert len(frames) == len(anim)
    want = np.array([[f["x"], f["y"], f["z"]] for f in frames]).transpose(0, 2, 1)
    # The JSON stores the shortest text that reads back to the same f64: equality.
    assert want.shape == anim.positions.shape
    np.testing.assert_array_equal(anim.positions, want)
    np.testing.assert_array_equal(anim.times, [f["t"] for f in frames])
    np.testing.assert_array_equal(anim.headings, [f["heading"] for f in frames])
    np.testing.assert_array_equal(anim.savings, [f["e"] for f in frames])
    assert anim.stages == [(s["name"], s["start"], s["end"]) for s in doc["stages"]]
    # And read back through the package, the file gives the same arrays.
    again = formation.read_animation(out)
    np.testing.assert_array_equal(again.positions, anim.positions)


def test_shapes_and_dtypes(anim):
    n, b = len(anim), anim.birds
    assert b == 9 and n > 4 * anim.fps
    assert anim.positions.shape == (n, b, 3)
    for name in ["headings", "banks", "pitches", "wing_phase", "speeds", "savings", "xi"]:
        a = getattr(anim, name)
        assert a.shape == (n, b), name
        assert a.dtype == np.float64, name
        assert np.isfinite(a).all(), name
    assert anim.positions.dtype == np.float64 and anim.times.dtype == np.float64
    assert np.all(np.diff(anim.times) > 0)
    assert ((anim.wing_phase >= 0) & (anim.wing_phase < 2 * np.pi)).all()
    # Munk: in the steady flight, xi sums to 1 in every frame (each xi rounded to 1e-6, as
    # the animation file stores it).
    name, start, end = anim.stages[-1]
    assert name == "steady"
    np.testing.assert_allclose(anim.xi[start:end].sum(axis=1), 1.0, rtol=0, atol=0.5e-6 * b + 1e-12)


def test_same_seed_same_motion_and_another_seed_differs():
    a = formation.animate(EXAMPLE, birds=5, seconds=2, seed=11)
    b = formation.animate(EXAMPLE, birds=5, seconds=2, seed=11)
    c = formation.animate(EXAMPLE, birds=5, seconds=2, seed=12)
    np.testing.assert_array_equal(a.positions, b.positions)
    assert a.positions.shape != c.positions.shape or not np.array_equal(a.positions, c.positions)


def test_land_and_land_on_end_in_a_landing_at_rest(tmp_path):
    # land=True: a final 'landing' stage, the flock at rest on the ground at the end; the same
    # motion as the command line's --land.
    a = formation.animate(EXAMPLE, birds=5, seconds=2, seed=4, land=True)
    name, start, end = a.stages[-1]
    assert name == "landing" and end == len(a) and start < end
    assert (a.speeds[-1] == 0).all()
    assert (a.positions[-1, :, 2] >= 0).all() and (a.positions[-1, :, 2] < 0.5).all()
    out = tmp_path / "land.json"
    cli("animate", EXAMPLE, "--birds", 5, "--seconds", 2, "--seed", 4, "--land", "--quiet", "-o", out)
    doc = json.loads(out.read_text())
    want = np.array([[f["x"], f["y"], f["z"]] for f in doc["frames"]]).transpose(0, 2, 1)
    np.testing.assert_array_equal(a.positions, want)
    # land_on="water" lands on water (implies land): bodies float, lower than on the ground.
    w = formation.animate(EXAMPLE, birds=5, seconds=2, seed=4, land_on="water")
    assert w.stages[-1][0] == "landing"
    assert (w.speeds[-1] == 0).all()
    assert w.positions[-1, :, 2].mean() < a.positions[-1, :, 2].mean()
    # Without land: no landing stage.
    assert formation.animate(EXAMPLE, birds=5, seconds=2, seed=4).stages[-1][0] == "steady"
    # A surface the library does not know is a ValueError naming the option.
    with pytest.raises(ValueError, match="landing.surface"):
        formation.animate(EXAMPLE, birds=5, seconds=2, seed=4, land_on="lava")


def test_options_by_path_and_by_section():
    a = formation.animate(EXAMPLE, birds=5, seconds=2, initiation=False, **{"steady.fps": 10})
    b = formation.animate(EXAMPLE, birds=5, seconds=2, initiation=False, steady={"fps": 10})
    assert a.fps == 10 and len(a) == 20
    np.testing.assert_array_equal(a.positions, b.positions)
    assert a.stages == [("steady", 0, 20)]
    assert "fps" in formation.default_options()["steady"]
    # The progress bar (drawn only on a terminal) changes nothing in the motion.
    c = formation.animate(EXAMPLE, birds=5, seconds=2, initiation=False, steady={"fps": 10}, progress=True)
    np.testing.assert_array_equal(c.positions, a.positions)


@pytest.mark.parametrize(
    "kwargs, flag_args, words",
    [
        ({"birds": 0}, ["--birds", "0"], "steady.birds"),
        ({"seconds": -1}, ["--birds", "14", "--seconds=-1"], "seconds"),
        ({"steady": {"fps": -5}}, ["--birds", "14", "--fps=-5"], "steady.fps"),
    ],
)
def test_bad_input_raises_the_cli_message(kwargs, flag_args, words):
    with pytest.raises(ValueError) as e:
        formation.animate(EXAMPLE, **kwargs)
    msg = str(e.value)
    assert words in msg and "\n" not in msg
    r = cli("animate", EXAMPLE, *flag_args, "--quiet", "-o", "unused.json", check=False)
    assert r.returncode == 2
    # The CLI names its flag where the library names the option path; the rest is the same.
    cli_text = r.stderr.strip().split(": ", 2)[-1]
    assert msg.split(": ", 1)[-1] == cli_text


def test_unknown_option_lists_the_valid_ones():
    with pytest.raises(ValueError, match=r"steady\.fpss: unknown option; steady has: .*fps"):
        formation.animate(EXAMPLE, **{"steady.fpss": 30})
    with pytest.raises(ValueError, match=r"^steady\.fps: "):
        formation.animate(EXAMPLE, **{"steady.fps": "fast"})
    # A section given as a dict names the option inside it.
    with pytest.raises(ValueError, match=r"^steady\.fps: "):
        formation.animate(EXAMPLE, steady={"fps": "fast"})
    with pytest.raises(ValueError, match=r"^initiate\.nope: unknown option"):
        formation.animate(EXAMPLE, initiate={"nope": 1})


def test_missing_file_is_an_os_error(tmp_path):
    with pytest.raises(OSError) as e:
        formation.animate(tmp_path / "nope.json")
    assert "nope.json" in str(e.value)


def test_to_pandas_columns_equal_the_cli_csv_header(tmp_path, anim):
    pd = pytest.importorskip("pandas")
    out = tmp_path / "cli.csv"
    cli("animate", EXAMPLE, "--birds", 9, "--seconds", 4, "--seed", 3, "--quiet", "-o", out)
    header = out.read_text().splitlines()[0].split(",")
    df = anim.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == header
    assert len(df) == len(anim) * anim.birds
    np.testing.assert_array_equal(df["x"].to_numpy().reshape(len(anim), anim.birds), anim.positions[..., 0])
    assert anim.to_csv() == out.read_text()


def test_write_every_format_and_bad_render_option(tmp_path, anim):
    anim.write(tmp_path / "a.json", tmp_path / "a.csv", tmp_path / "a.glb")
    for name in ["a.json", "a.csv", "a.glb"]:
        assert (tmp_path / name).stat().st_size > 0
    assert (tmp_path / "a.glb").read_bytes()[:4] == b"glTF"
    np.testing.assert_array_equal(formation.read_animation(tmp_path / "a.json").positions, anim.positions)
    with pytest.raises(ValueError, match="render.width"):
        anim.write(tmp_path / "b.gif", width=-3)
    assert not (tmp_path / "b.gif").exists()


def test_binary_frames_with_numpy_and_read_back(tmp_path, anim):
    anim.write(tmp_path / "b.json", binary_frames=True)
    head = json.loads((tmp_path / "b.json").read_text())
    ff = head["frames_file"]
    assert "frames" not in head and ff["path"] == "b.frames"
    # The recipe of docs/formats.md: one record a frame, the time then each field's birds.
    record = np.dtype([("t", "<f8")] + [(f, "<f4", (head["birds"],)) for f in ff["fields"]])
    frames = np.fromfile(tmp_path / ff["path"], dtype=record, count=ff["frames"], offset=16)
    assert frames.shape == (ff["frames"],) == (len(anim),)
    np.testing.assert_array_equal(frames["t"], anim.times)
    np.testing.assert_array_equal(frames["x"], anim.positions[..., 0].astype(np.float32))
    np.testing.assert_array_equal(frames["e"], anim.savings.astype(np.float32))
    again = formation.read_animation(tmp_path / "b.json")
    np.testing.assert_array_equal(again.positions, anim.positions.astype(np.float32).astype(np.float64))


def test_gil_released_during_animate():
    # With a long switch interval, a thread waiting for the GIL only runs when the holder
    # releases it of its own accord: a counter that moves while `animate` runs proves that
    # `animate` released it (held, the counter would stand still for the whole call).
    count = 0
    started, done = threading.Event(), threading.Event()

    def spin():
        nonlocal count
        started.set()
        while not done.is_set():
            count += 1

    old = sys.getswitchinterval()
    t = threading.Thread(target=spin)
    t.start()
    started.wait()
    sys.setswitchinterval(0.5)
    try:
        before = count
        anim = formation.animate(EXAMPLE, birds=60, seconds=20, seed=1)
        during = count - before
    finally:
        sys.setswitchinterval(old)
        done.set()
        t.join()
    assert anim.birds == 60
    assert during > 1000, during


def test_annotations_extract_and_params():
    frames = [
        [[480 + s * 36 * r + 1.5 * f, 200 + 24 * r - 1.5 * f] for r in range(5) for s in ((-1, 1) if r else (1,))]
        for f in range(3)
    ]
    ann = formation.read_annotations(frames, wingspan_px=40, name="hand-marked")
    assert len(ann) == 3
    params = formation.extract(ann, seed=2)
    assert params.birds == 9
    d = params.to_dict()
    assert d["birds"] == 9 and len(params.frames) == 3 == len(d["frames"])
    a = formation.animate(params, birds=12, seconds=2, seed=2)
    assert a.positions.shape[1] == 12
    on_disk = formation.extract(EXAMPLE)
    assert on_disk.birds > 2
    with pytest.raises(ValueError, match="read.wingspan_px"):
        formation.read_annotations(frames)
    with pytest.raises(ValueError, match="frame 0"):
        formation.read_annotations([[1, 2, 3]], wingspan_px=40)


def test_power_matches_the_cli_and_munk(tmp_path):
    x = np.array([0.0, -0.8, 0.8, -1.6, 1.6])
    y = np.array([0.0, 1.0, 1.0, 2.0, 2.0])
    e, xi, total = formation.power(x, y)
    assert e.dtype == np.float64 and e.shape == (5,)
    assert total == pytest.approx(e.sum(), rel=1e-12)
    np.testing.assert_allclose(xi, e / total, rtol=1e-12)
    shape = tmp_path / "shape.json"
    shape.write_text(json.dumps({"birds": [{"x": a, "y": b} for a, b in zip(x, y)]}))
    doc = json.loads(cli("power", shape, "--json").stdout)
    np.testing.assert_allclose(e, [b["e"] for b in doc["birds"]], rtol=1e-12)
    # Munk's stagger theorem: moving birds fore and aft leaves the total unchanged.
    _, _, total2 = formation.power(x, y * 3)
    assert total2 == pytest.approx(total, rel=1e-9)
    with pytest.raises(ValueError, match="collide"):
        formation.power([0, 0.5], [0, 0])
    with pytest.raises(ValueError, match="core_radius"):
        formation.power(x, y, core_radius=-1)
    with pytest.raises(ValueError, match="z: "):
        formation.power(x, y, z=np.ones(4))


def test_power_with_heights_is_the_3d_wake_of_the_cli(tmp_path):
    x = np.array([0.0, -0.77, 0.77, -1.54, 1.54])
    y = np.array([0.0, 1.24, 1.24, 2.48, 2.48])
    z = np.array([0.0, 0.06, -0.06, 0.14, 0.0])
    e, xi, total = formation.power(x, y, z=z)
    shape = tmp_path / "shape.json"
    birds = [{"x": a, "y": b, "z": c} for a, b, c in zip(x, y, z)]
    shape.write_text(json.dumps({"birds": birds}))
    doc = json.loads(cli("power", shape, "--wake", "3d", "--json").stdout)
    np.testing.assert_allclose(e, [b["e"] for b in doc["birds"]], rtol=1e-12)
    assert total == pytest.approx(e.sum(), rel=1e-12)
    # Heights cost savings; at zero heights the 3-D wake is the planar one.
    e_planar, _, total_planar = formation.power(x, y)
    assert total < total_planar
    e0, _, _ = formation.power(x, y, z=np.zeros(5))
    np.testing.assert_allclose(e0, e_planar, rtol=1e-10, atol=1e-12)
    # wake="planar" ignores the heights, as --wake planar does.
    e_ignored, _, _ = formation.power(x, y, z=z, wake="planar")
    np.testing.assert_allclose(e_ignored, e_planar, rtol=1e-12)
    with pytest.raises(ValueError, match=r"z\[1\]"):
        formation.power(x, y, z=[0.0, float("nan"), 0.0, 0.0, 0.0])


def test_solve_reaches_the_targets_power_gives():
    x = np.array([0.0, -0.85, 0.85, -1.7, 1.7])
    y = np.array([0.0, 1.2, 1.4, 2.5, 2.2])
    _, xi, _ = formation.power(x, y)
    r = formation.solve(x, xi)
    assert r["converged"] and r["residual"] <= 1e-9
    _, xi2, _ = formation.power(x, r["y"])
    np.testing.assert_allclose(xi2, xi, atol=1e-8)
    with pytest.raises(ValueError):
        formation.solve([0.0], [1.0])


def test_command_line_from_the_package(tmp_path):
    # The console script beside this Python, as `pip install` puts it.
    exe = Path(sys.executable).parent / "formation"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "formation._cli"]
    out = tmp_path / "p.json"
    r = subprocess.run(cmd + ["animate", str(EXAMPLE), "--birds", "9", "--seconds", "4", "--seed", "3",
                              "--quiet", "-o", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    anim = formation.animate(EXAMPLE, birds=9, seconds=4, seed=3)
    np.testing.assert_array_equal(formation.read_animation(out).positions, anim.positions)
    bad = subprocess.run(cmd + ["animate", str(EXAMPLE), "--birds", "0", "-o", str(out)],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.startswith("error: ") and "--birds" in bad.stderr


def test_options_left_out_at_their_default_can_be_set():
    # aero.wake is not in default_options() while planar, yet it is an option like the others.
    kw = dict(birds=7, seconds=3, seed=1)
    planar = formation.animate(EXAMPLE, **kw)
    wake3d = formation.animate(EXAMPLE, **kw, **{"steady.aero.wake": "3d"})
    np.testing.assert_array_equal(planar.positions, wake3d.positions)
    assert not np.array_equal(np.nan_to_num(planar.savings), np.nan_to_num(wake3d.savings))
    with pytest.raises(ValueError, match="steady.aero.wake: unknown variant"):
        formation.animate(EXAMPLE, **kw, **{"steady.aero.wake": "4d"})
    with pytest.raises(ValueError, match="steady.aero.bogus: unknown option"):
        formation.animate(EXAMPLE, **kw, **{"steady.aero.bogus": 1})


def test_progress_callable_and_notebook_bar(capsys):
    calls = []
    kw = dict(birds=9, seconds=4, seed=2)
    a = formation.animate(EXAMPLE, progress=lambda s, d, t: calls.append((s, d, t)), **kw)
    b = formation.animate(EXAMPLE, **kw)
    np.testing.assert_array_equal(a.positions, b.positions)
    stages = [s for s, _, _ in calls]
    assert stages, "the callable was never called"
    for s, d, t in calls:
        assert isinstance(s, str) and 0 <= d <= t
    # Each stage is reported from 0 to its total, done never going back within a stage.
    for stage in dict.fromkeys(stages):
        mine = [(d, t) for s, d, t in calls if s == stage]
        assert mine[0][0] == 0 and mine[-1][0] == mine[-1][1]
        assert all(x[0] <= y[0] for x, y in zip(mine, mine[1:]))

    def boom(stage, done, total):
        raise KeyError("stop here")

    with pytest.raises(KeyError, match="stop here"):
        formation.animate(EXAMPLE, progress=boom, **kw)
    # progress=True away from a terminal (pytest captures stderr, as a notebook does): a bar
    # drawn through sys.stderr, not silence.
    formation.animate(EXAMPLE, progress=True, **kw)
    err = capsys.readouterr().err
    assert "[" in err and "/" in err


def test_bundled_examples_are_the_repositorys():
    names = formation.examples()
    for n in ["barnacle_geese_v.json", "cranes_v_dltdv.csv", "snow_geese_j.csv", "pelicans_u_labelme"]:
        assert n in names
        path = Path(formation.example(n))
        assert path.exists()
        mine = ROOT / "examples_data" / n
        if mine.is_file():
            assert path.read_bytes() == mine.read_bytes(), f"{n} differs from examples_data/"
        elif mine.is_dir():
            assert sorted(p.name for p in path.iterdir()) == sorted(p.name for p in mine.iterdir())
    # The name without its extension works too; an unknown one names those there are.
    assert formation.example("barnacle_geese_v") == formation.example("barnacle_geese_v.json")
    with pytest.raises(ValueError, match="barnacle_geese_v.json"):
        formation.example("ravens")
    with pytest.raises(ValueError):
        formation.example("../README.md")


def test_the_readme_snippet_runs_from_any_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    params = formation.extract(formation.example("barnacle_geese_v.json"), seed=1)
    anim = formation.animate(params, birds=5, seconds=2, seed=1, initiation=False)
    assert anim.positions.shape[1] == 5


def test_warnings_are_formation_warnings_in_pythons_spelling():
    # The barnacle geese read as flying down the image: the formation opens forward.
    ann = formation.read_annotations(EXAMPLE, heading="down")
    with pytest.warns(formation.FormationWarning) as got:
        params = formation.extract(ann, seed=1)
    text = " ".join(str(w.message) for w in got)
    assert "opens forward" in text
    assert "read_annotations(..., heading=" in text and "read.heading" not in text
    assert params.summary["warnings"], "the warning is also kept in the summary"
    # Given by option, the message names the option section.
    with pytest.warns(formation.FormationWarning, match=r'read=\{"heading": "up"\}'):
        formation.extract(EXAMPLE, seed=1, read={"heading": "down"})
    # strict: the first warning is a ValueError, nothing returned.
    with pytest.raises(ValueError, match="^strict: .*opens forward"):
        formation.extract(ann, seed=1, strict=True)
    # A clean input warns nothing, strict or not.
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", formation.FormationWarning)
        formation.extract(EXAMPLE, seed=1, strict=True)


def test_animate_raises_the_runs_warnings():
    ann = formation.read_annotations(EXAMPLE, heading="down")
    with pytest.warns(formation.FormationWarning, match=r"opens forward.*read_annotations\(\.\.\., heading=\"up\"\)"):
        anim = formation.animate(ann, birds=5, seconds=2, seed=1, initiation=False)
    assert anim.birds == 5
    # A heading option given as the CLI spells it ("down") is accepted by path too.
    with pytest.warns(formation.FormationWarning, match=r'read=\{"heading": "up"\}'):
        formation.animate(EXAMPLE, birds=5, seconds=2, seed=1, initiation=False, **{"read.heading": "down"})
    with pytest.raises(ValueError, match="^strict: .*opens forward"):
        formation.animate(ann, birds=5, seconds=2, seed=1, initiation=False, strict=True)


def test_no_leaked_names_and_all_is_the_api():
    public = {n for n in dir(formation) if not n.startswith("_")}
    assert "annotations" not in public
    for n in formation.__all__:
        assert hasattr(formation, n), n
    assert "FormationWarning" in formation.__all__ and "example" in formation.__all__


def test_notebook_view_is_a_player_in_an_isolated_frame(anim):
    html = anim._repr_html_()
    assert html.startswith("<div>") and "<iframe srcdoc=" in html
    assert "clearance" in html and "9</td>" in html
    # The player's own markup is escaped inside srcdoc: no raw script tag in the cell.
    assert "<script" not in html and "&lt;script" in html


def test_to_pandas_without_pandas_says_how_to_install_it(anim, monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match="pip install pandas"):
        anim.to_pandas()


def test_installed_command_help_is_the_tools():
    out = subprocess.run(
        [sys.executable, "-m", "formation._cli", "--help"], capture_output=True, text=True, check=True
    ).stdout
    first = out.splitlines()[0]
    assert "Animate bird flocks" in first and "maturin" not in first and "bindings" not in first
