"""tesseral.rsmc against a Python model of the surface it returns."""

import numpy as np
import pytest

import tesseral as t

NEIGHBOURS = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]


def exposed_faces(voxels):
    cells = set(map(tuple, voxels.tolist()))
    return sum((x + a, y + b, z + c) not in cells for x, y, z in cells for a, b, c in NEIGHBOURS)


def radius_of_gyration(voxels):
    c = voxels.astype(float) + 0.5
    return float(np.sqrt(((c - c.mean(axis=0)) ** 2).sum(axis=1).mean()))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_final_row_describes_the_returned_solid(seed):
    run = t.rsmc(steps=5000, beta=0.3, seed=seed, sample_every=500)
    v = run["voxels"]
    assert v.dtype == np.int64 and v.shape[1] == 3
    assert len(set(map(tuple, v.tolist()))) == len(v)
    assert run["volume"][-1] == len(v)
    assert run["area"][-1] == exposed_faces(v) == run["faces"]
    assert run["radius_of_gyration"][-1] == pytest.approx(radius_of_gyration(v), rel=1e-9)
    assert list(run["step"]) == list(range(0, 5001, 500))
    k = run["counters"]
    assert k["steps"] == 5000
    assert k["accepted"] + k["illegal"] + k["capped"] + k["refused"] == k["steps"]
    assert ((run["acceptance"] >= 0) & (run["acceptance"] <= 1)).all()


def test_same_seed_same_trajectory_on_both_backends():
    a = t.rsmc(steps=4000, beta=0.2, seed=11, sample_every=100)
    b = t.rsmc(steps=4000, beta=0.2, seed=11, sample_every=100, backend="dense")
    for key in ["step", "area", "volume", "radius_of_gyration", "acceptance"]:
        assert np.array_equal(a[key], b[key]), key
    assert sorted(map(tuple, a["voxels"].tolist())) == sorted(map(tuple, b["voxels"].tolist()))
    c = t.rsmc(steps=4000, beta=0.2, seed=12, sample_every=100)
    assert not np.array_equal(a["area"], c["area"])


def test_start_shapes():
    box = t.rsmc(steps=0, start="box:3x2x1")
    assert box["volume"][0] == 6 and box["area"][0] == 22
    arr = t.rsmc(steps=0, start=np.array([[0, 0, 0], [1, 0, 0]], dtype=np.int64))
    assert arr["volume"][0] == 2 and arr["area"][0] == 10


def test_area_cap_holds_along_the_run():
    run = t.rsmc(steps=20_000, max_area=30, seed=5, sample_every=100)
    assert run["area"].max() <= 30
    assert run["counters"]["capped"] > 0


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"sample_every": 0}, "sample_every"),
        ({"backend": "sparse"}, "backend"),
        ({"start": "box:0x1x1"}, "box"),
        ({"start": "ball"}, "start"),
        ({"beta": float("nan")}, "beta"),
        ({"max_area": 4}, "max_area"),
    ],
)
def test_bad_arguments_name_themselves(kwargs, needle):
    with pytest.raises(ValueError, match=needle):
        t.rsmc(steps=10, **kwargs)
