"""Pickling: `Params`, `Animation` and `Annotations` survive `pickle` (every protocol), `copy`
and a `multiprocessing` pool exactly (every float's bits, the run's options), as joblib and Dask
need; a damaged state is a ValueError.

Run from the repository root after installing the package: `python -m pytest python/tests`.
"""

import copy
import multiprocessing
import pickle

import numpy as np
import pytest

import formation

ARRAYS = ["positions", "headings", "banks", "pitches", "wing_phase", "speeds", "savings", "xi", "times"]


@pytest.fixture(scope="module")
def params():
    return formation.extract(formation.example("barnacle_geese_v.json"), seed=2)


@pytest.fixture(scope="module")
def anim(params):
    # Take-off and steady flight: every optional per-bird field (bank, pitch, e, xi, wing phase).
    return formation.animate(params, birds=7, seconds=3, seed=5)


def same_bits(a, b):
    for name in ARRAYS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape and x.dtype == y.dtype, name
        assert x.tobytes() == y.tobytes(), f"{name} differs after the round trip"


@pytest.mark.parametrize("protocol", range(pickle.HIGHEST_PROTOCOL + 1))
def test_every_protocol_round_trips_exactly(protocol, params, anim):
    ann = formation.read_annotations(formation.example("cranes_v_dltdv.csv"), wingspan_px=22, heading=300)
    for obj in (params, anim, ann):
        back = pickle.loads(pickle.dumps(obj, protocol=protocol))
        assert type(back) is type(obj)
        assert back == obj
        assert repr(back) == repr(obj)
    back = pickle.loads(pickle.dumps(anim, protocol=protocol))
    same_bits(anim, back)
    assert back.stages == anim.stages
    assert (back.birds, back.fps, back.seed, back.wingspan_m, back.species) == (
        anim.birds, anim.fps, anim.seed, anim.wingspan_m, anim.species)
    assert back.to_csv() == anim.to_csv()
    assert back.to_json() == anim.to_json()
    p = pickle.loads(pickle.dumps(params, protocol=protocol))
    assert p.to_json() == params.to_json() and p.summary == params.summary and p.frames == params.frames


def test_the_run_s_options_travel_with_the_animation(params):
    wide = formation.animate(params, birds=5, seconds=2, seed=1, initiation=False)
    narrow = formation.animate(params, birds=5, seconds=2, seed=1, initiation=False, render={"width": 320})
    assert wide != narrow, "the render options are part of an Animation (write uses them)"
    same_bits(wide, narrow)
    assert pickle.loads(pickle.dumps(narrow)) == narrow
    assert pickle.loads(pickle.dumps(narrow)) != wide


def test_copy_and_deepcopy(params, anim):
    for obj in (params, anim):
        assert copy.copy(obj) == obj
        assert copy.deepcopy(obj) == obj
        # Immutable, so a copy may be (and is) the object itself, as for str and tuple.
        assert copy.deepcopy({"x": obj})["x"] == obj


def test_a_damaged_state_is_a_value_error(anim, params):
    state = anim.__reduce__()[1][1]
    for bad in (b"", b"junk", state[:-3], state + b"\0"):
        with pytest.raises(ValueError, match="unpickling a formation.Animation"):
            formation._unpickle("Animation", bad)
    with pytest.raises(ValueError, match="unpickling a formation.Params"):
        formation._unpickle("Params", params.__reduce__()[1][1][:-5])
    with pytest.raises(ValueError, match="not a formation class"):
        formation._unpickle("Flock", b"{}")


def _mean_savings(a):
    return np.nanmean(a.savings, axis=0)


def _animate(seed):
    return formation.animate(formation.example("barnacle_geese_v.json"), birds=5, seconds=2, seed=seed,
                             initiation=False)


def test_a_process_pool_maps_over_animations(anim):
    # "spawn" (the default on macOS and Windows, and the safe start for a process whose library
    # has threads): the arguments and the results cross the process boundary as pickles.
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(2) as pool:
        means = pool.map_async(_mean_savings, [anim, anim]).get(timeout=600)
        made = pool.map_async(_animate, [11, 12]).get(timeout=600)
    for m in means:
        assert m.tobytes() == _mean_savings(anim).tobytes()
    for seed, a in zip([11, 12], made):
        here = _animate(seed)
        assert a == here, f"seed {seed}: an animation made in a worker differs from one made here"
        same_bits(a, here)
