"""DynamicOctree.insert_scan: a binary map fed range scans, against a set model."""

import numpy as np
import pytest

import tesseral as t


def test_a_ray_clears_its_cells_and_sets_its_end():
    d = t.DynamicOctree()
    d.insert(np.array([[2, 0, 0], [3, 0, 0], [9, 9, 9]], dtype=np.int64))
    s = d.insert_scan((0.5, 0.5, 0.5), np.array([[5.5, 0.5, 0.5]]))
    assert s["hits"] == 1 and s["misses"] == 5
    assert s["inserted"] == 1 and s["removed"] == 2
    assert sorted(map(tuple, d.voxels().tolist())) == [(5, 0, 0), (9, 9, 9)]


def test_hit_wins_over_a_crossing_in_one_scan():
    d = t.DynamicOctree()
    # The second ray crosses (3, 0, 0), which the first one hits.
    d.insert_scan((0.5, 0.5, 0.5), np.array([[3.5, 0.5, 0.5], [6.5, 0.5, 0.5]]))
    assert sorted(map(tuple, d.voxels().tolist())) == [(3, 0, 0), (6, 0, 0)]


def test_max_range_clears_without_setting():
    d = t.DynamicOctree()
    d.insert(np.array([[1, 0, 0], [8, 0, 0]], dtype=np.int64))
    s = d.insert_scan((0.5, 0.5, 0.5), np.array([[8.5, 0.5, 0.5]]), max_range=4.0)
    assert s["hits"] == 0 and s["inserted"] == 0
    assert sorted(map(tuple, d.voxels().tolist())) == [(8, 0, 0)]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_random_scans_follow_the_occupancy_maps_cells(seed):
    # Each scan, applied to a set model from the cells one fresh OccupancyMap scan
    # marks (its own tests hold it against a brute-force segment-box model).
    rng = np.random.default_rng(seed)
    d = t.DynamicOctree()
    model = set()
    for _ in range(5):
        origin = rng.uniform(-4, 4, size=3)
        pts = origin + rng.normal(0, 6, size=(200, 3))
        m = t.OccupancyMap(1.0)
        m.insert_scan(tuple(origin), pts)
        d.insert_scan(tuple(origin), pts)
        # The fresh map's known cells, read from a dense box around the scan.
        lo_box = np.floor(np.minimum(pts.min(axis=0), origin)).astype(np.int64) - 1
        hi_box = np.floor(np.maximum(pts.max(axis=0), origin)).astype(np.int64) + 2
        g = np.mgrid[lo_box[0]:hi_box[0], lo_box[1]:hi_box[1], lo_box[2]:hi_box[2]]
        box = g.reshape(3, -1).T.astype(np.int64)
        v = m.log_odds(box)
        for c, l in zip(map(tuple, box.tolist()), v):
            if np.isnan(l):
                continue
            if l > 0:
                model.add(c)
            else:
                model.discard(c)
        assert set(map(tuple, d.voxels().tolist())) == model
        assert len(d) == len(model)
