"""A sweep on Dask: a `LocalCluster` of two worker processes maps `animate` over four tasks (seeds
and flock sizes), and a `Params` scattered to the workers is used there; every animation that
comes back equals the same run made here, bit for bit. The same code runs on a cluster by giving
`Client` the scheduler's address instead of a `LocalCluster`.

Skipped when dask.distributed is not installed, unless FORMATION_REQUIRE_DASK=1 (CI installs it
and sets that, so a missing Dask fails there instead of passing unseen).
"""

import logging
import os

import pytest

import formation

if os.environ.get("FORMATION_REQUIRE_DASK") == "1":
    import distributed
else:
    distributed = pytest.importorskip("distributed")

ARRAYS = ["positions", "headings", "speeds", "savings", "times"]


def flock(params, seed, birds):
    return formation.animate(params, birds=birds, seconds=2, seed=seed)


def test_a_four_task_sweep_on_a_local_cluster_equals_the_runs_made_here():
    params = formation.extract(formation.example("barnacle_geese_v.json"), seed=1)
    tasks = [(0, 7), (1, 7), (2, 12), (3, 12)]
    with distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    ) as cluster, distributed.Client(cluster) as client:
        remote = client.scatter(params, broadcast=True)
        futures = [client.submit(flock, remote, seed, birds, pure=False) for seed, birds in tasks]
        anims = client.gather(futures)
        # The workers are other processes: they had to unpickle the Params and pickle back the
        # animations.
        pids = set(client.run(os.getpid).values())
        assert os.getpid() not in pids and len(pids) == 2
    assert len(anims) == 4
    for (seed, birds), a in zip(tasks, anims):
        here = flock(params, seed, birds)
        assert a == here, f"seed {seed}, {birds} birds differ"
        assert a.positions.shape[1] == birds
        for name in ARRAYS:
            assert getattr(a, name).tobytes() == getattr(here, name).tobytes(), name
