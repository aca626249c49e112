"""The occupancy map: scans in, cell states out, against a small model."""

import numpy as np
import pytest

import tesseral as t


def test_a_ray_misses_its_cells_and_hits_its_end():
    m = t.OccupancyMap(0.1)
    s = m.insert_scan((0.05, 0.05, 0.05), np.array([[1.05, 0.05, 0.05]]))
    assert s == {"points": 1, "rays": 1, "skipped": 0, "hits": 1, "misses": 10}
    cells = np.array([[10, 0, 0], [3, 0, 0], [11, 0, 0]], dtype=np.int64)
    assert list(m.state(cells)) == [2, 1, 0]
    lo = m.log_odds(cells)
    assert lo[0] == pytest.approx(0.847, abs=1e-3)
    assert lo[1] == pytest.approx(-0.405, abs=1e-3)
    assert np.isnan(lo[2])


def test_max_range_clears_without_a_hit_and_nan_points_are_skipped():
    m = t.OccupancyMap(0.1)
    pts = np.array([[5.05, 0.05, 0.05], [np.nan, 0.0, 0.0]])
    s = m.insert_scan((0.05, 0.05, 0.05), pts, max_range=1.0)
    assert s["skipped"] == 1 and s["hits"] == 0 and s["misses"] == 10
    st = m.stats()
    assert st["occupied"] == 0 and st["free"] == 10
    assert list(m.cells_of(np.array([[5.05, 0.05, 0.05]]))[0]) == [50, 0, 0]


def test_repeated_scans_match_a_counting_model():
    rng = np.random.default_rng(4)
    m = t.OccupancyMap(0.25, prob_hit=0.7, prob_miss=0.4)
    # Rays along +x from one origin: cells crossed are exactly those before the end.
    hits, misses = {}, {}
    for _ in range(6):
        ends = rng.integers(1, 12, size=20)
        ys = rng.integers(0, 4, size=20)
        pts = np.stack([ends * 0.25 + 0.1, ys * 0.25 + 0.1, np.full(20, 0.1)], axis=1)
        for y in range(4):
            sel = ys == y
            if not sel.any():
                continue
            m.insert_scan((0.1, y * 0.25 + 0.1, 0.1), pts[sel])
            hit = set(int(e) for e in ends[sel])
            miss = set(range(0, max(hit))) - hit
            for x in hit:
                hits[(x, y)] = hits.get((x, y), 0) + 1
            for x in miss:
                misses[(x, y)] = misses.get((x, y), 0) + 1
    assert m.stats()["occupied"] + m.stats()["free"] == len(set(hits) | set(misses))
    with pytest.raises(ValueError):
        t.OccupancyMap(0.0)
    with pytest.raises(ValueError):
        t.OccupancyMap(0.1, prob_hit=0.3)


def test_a_far_point_is_refused_before_it_is_cast():
    m = t.OccupancyMap(0.05)
    far = np.array([[1.0, 0.0, 0.0], [1e9, 0.0, 0.0]])
    with pytest.raises(ValueError, match="past max_cells=10000000000"):
        m.insert_scan((0.0, 0.0, 0.0), far)
    assert m.stats()["free"] == 0  # nothing was cast
    s = m.insert_scan((0.0, 0.0, 0.0), far, max_range=10.0)
    assert s["rays"] == 2 and s["hits"] == 1
    with pytest.raises(ValueError, match="max_cells=5"):
        m.insert_scan((0.0, 0.0, 0.0), far[:1], max_cells=5)
    d = t.DynamicOctree()
    with pytest.raises(ValueError, match="past max_cells"):
        d.insert_scan((0.5, 0.5, 0.5), np.array([[1e12, 0.5, 0.5]]))
    assert len(d) == 0


def test_batched_log_odds_agree_with_one_cell_at_a_time_and_with_state():
    # `log_odds` on many cells goes through the batched lookup (batches of 32 whose
    # memory accesses are prefetched together); one row at a time, and `state`,
    # must give the same answers, far from the origin and at negative keys too.
    rng = np.random.default_rng(11)
    m = t.OccupancyMap(0.1)
    origin = np.array([-1.0e6, 2.5e5, -3.0])
    for _ in range(3):
        pts = origin + rng.uniform(-4.0, 4.0, size=(400, 3))
        m.insert_scan(tuple(origin), pts)
    base = m.cells_of(origin[None, :])[0]
    cells = base + rng.integers(-45, 45, size=(3001, 3))
    cells = np.concatenate([cells, m.cells_of(pts)]).astype(np.int64)
    many = m.log_odds(cells)
    one = np.array([m.log_odds(c[None, :])[0] for c in cells], dtype=np.float32)
    np.testing.assert_array_equal(many, one)
    st = m.state(cells)
    assert np.array_equal(np.isnan(many), st == 0)
    assert (st == 2).any() and (st == 1).any() and (st == 0).any()
    assert np.array_equal(many[st == 2] >= 0, np.ones((st == 2).sum(), dtype=bool))


def test_insert_scans_gives_the_map_and_counts_of_a_loop_of_insert_scan():
    rng = np.random.default_rng(5)
    scans = []
    for _ in range(5):
        origin = tuple(rng.uniform(-1.0, 1.0, 3))
        pts = rng.uniform(-3.0, 3.0, (400, 3))
        pts[::37] = np.nan
        scans.append((origin, pts))
    one = t.OccupancyMap(0.1)
    want = [one.insert_scan(o, p, max_range=2.5) for o, p in scans]
    m = t.OccupancyMap(0.1)
    got = m.insert_scans(scans, max_range=2.5)
    assert got == want
    # The same cells; the batch ends tidied (its arenas compacted), so it holds
    # no more bytes than the loop.
    batch, loop = m.stats(), one.stats()
    assert batch.pop("bytes") <= loop.pop("bytes")
    assert batch == loop
    one.shrink_to_fit()
    assert one.stats() == m.stats()
    ends = np.concatenate([p for _, p in scans])
    cells = m.cells_of(ends[~np.isnan(ends).any(axis=1)])
    np.testing.assert_array_equal(m.log_odds(cells), one.log_odds(cells))  # NaN: unknown
    assert (m.state(cells) == one.state(cells)).all()


def test_insert_scans_checks_every_scans_work_before_casting_any():
    m = t.OccupancyMap(0.1)
    near = np.array([[1.0, 0.0, 0.0]])
    far = np.array([[1.0e9, 0.0, 0.0]])
    with pytest.raises(ValueError, match="scan 1: .*max_cells"):
        m.insert_scans([((0.0, 0.0, 0.0), near), ((0.0, 0.0, 0.0), far)])
    assert m.stats()["occupied"] == 0 and m.stats()["free"] == 0


def _room_scans():
    rng = np.random.default_rng(11)
    scans = []
    for k in range(3):
        d = rng.normal(size=(400, 3))
        d /= np.abs(d).max(axis=1, keepdims=True)  # onto the faces of a cube
        origin = (0.3 * k, 0.1, 0.2)
        scans.append((origin, np.asarray(origin) + 2.0 * d))
    return scans


def test_to_octree_is_the_cli_map_and_from_octree_reads_it_back(tmp_path):
    m = t.OccupancyMap(0.1)
    m.insert_scans(_room_scans())
    o = m.to_octree()
    st = m.stats()
    assert len(o) == st["occupied"]
    assert o.frame["voxel_size"] == pytest.approx(0.1)
    info = o.info()
    assert info["free_voxels"] == st["free"] and info["log_odds"]
    # The occupied voxels are the map's occupied cells.
    occ = o.voxels()
    assert list(m.state(occ)) == [2] * len(occ)
    # Through OctoMap's .ot and back: the same states and log-odds everywhere known.
    o.write(tmp_path / "map.ot")
    back = t.OccupancyMap.from_octree(t.Octree.read(tmp_path / "map.ot"))
    assert back.stats()["occupied"] == st["occupied"]
    assert back.stats()["free"] == st["free"]
    probe = np.concatenate([occ, m.cells_of(np.array([[0.05, 0.05, 0.05], [9.0, 9.0, 9.0]]))])
    assert list(back.state(probe)) == list(m.state(probe))
    a, b = m.log_odds(probe), back.log_odds(probe)
    known = ~np.isnan(a)
    assert np.array_equal(np.isnan(a), np.isnan(b))
    assert np.allclose(a[known], b[known], atol=1e-3)
    # A .bt keeps states only: occupied cells come back at the upper clamp.
    o.write(tmp_path / "map.bt")
    ml = t.OccupancyMap.from_octree(t.Octree.read(tmp_path / "map.bt"))
    assert list(ml.state(probe)) == list(m.state(probe))
    upper = np.log(0.971 / (1 - 0.971))
    assert np.allclose(ml.log_odds(occ), upper, atol=0.01)


def test_read_scans_places_clouds_and_logs_as_the_cli_does(tmp_path):
    scans = _room_scans()
    # A log: NODE x y z roll pitch yaw, then sensor-frame points.
    log = []
    for origin, pts in scans:
        log.append("NODE %r %r %r 0 0 0.5" % origin)
        c, s = np.cos(0.5), np.sin(0.5)
        rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        local = (pts - np.asarray(origin)) @ rot  # inverse of the yaw
        log.extend("%r %r %r" % tuple(p) for p in local.astype(np.float32).tolist())
    (tmp_path / "run.log").write_text("\n".join(log) + "\n")
    read = t.read_scans(tmp_path / "run.log")
    assert len(read) == 3
    for (o, p), (o2, p2) in zip(scans, read):
        assert o2 == pytest.approx(o, abs=1e-6)
        assert p2.shape == p.shape and np.allclose(p2, p, atol=1e-5)
    # A cloud: world points, with origin= (or pose=) placing the sensor; NaN rows kept.
    pts = np.vstack([scans[0][1], [[np.nan] * 3]])
    np.savetxt(tmp_path / "c.xyz", pts)
    [(o, p)] = t.read_scans(tmp_path / "c.xyz", origin=(0.0, 0.1, 0.2))
    assert o == (0.0, 0.1, 0.2) and p.shape == (401, 3) and np.isnan(p[-1]).all()
    [(o, p)] = t.read_scans(tmp_path / "c.xyz", pose=(1, 0, 0, 0, 0, 0))
    assert o == (1.0, 0.0, 0.0) and np.allclose(p[:-1], pts[:-1] + [1, 0, 0])
    # What it gives is what insert_scans takes.
    m = t.OccupancyMap(0.1)
    counts = m.insert_scans(t.read_scans(tmp_path / "c.xyz", origin=(0.0, 0.1, 0.2)))
    assert counts[0]["skipped"] == 1
    # Errors name the file.
    with pytest.raises(ValueError, match="own poses"):
        t.read_scans(tmp_path / "run.log", origin=(0, 0, 0))
    with pytest.raises(ValueError, match="not both"):
        t.read_scans(tmp_path / "c.xyz", origin=(0, 0, 0), pose=(0, 0, 0, 0, 0, 0))
    (tmp_path / "bad.xyz").write_text("1 2 3\n4 x 6\n")
    with pytest.raises(t.FormatError, match=r"bad.xyz:2:3"):
        t.read_scans(tmp_path / "bad.xyz")
    with pytest.raises(t.FormatError, match="nope.txt"):
        t.read_scans(tmp_path / "nope.txt")


def test_write_gives_the_bytes_of_the_octree_and_refuses_past_the_keys(tmp_path):
    m = t.OccupancyMap(0.1)
    m.insert_scans(_room_scans())
    for ext in ("bt", "ot"):
        m.write(tmp_path / f"direct.{ext}")
        m.to_octree().write(tmp_path / f"model.{ext}")
        direct = (tmp_path / f"direct.{ext}").read_bytes()
        assert direct == (tmp_path / f"model.{ext}").read_bytes()
    m.write(tmp_path / "map.tess")
    assert len(t.Octree.read(tmp_path / "map.tess")) == m.stats()["occupied"]
    far = t.OccupancyMap(0.1)
    far.insert_scan((4000.0, 0.0, 0.0), np.array([[4001.0, 0.0, 0.0]]))
    with pytest.raises(Exception, match="far.bt.*OctoMap"):
        far.write(tmp_path / "far.bt")
    assert not (tmp_path / "far.bt").exists()
    far.write(tmp_path / "far.tess")


def test_a_map_wider_than_an_octree_keeps_its_range_and_reads_back(tmp_path):
    m = t.OccupancyMap(0.5, prob_hit=0.8, threshold=0.6)
    m.insert_scans(_room_scans())
    # 3,000,000 cells off: past the 2^21 an octree holds on an axis.
    m.insert_scan((1.5e6, 0.25, 0.25), np.array([[1.5e6 + 3.0, 0.25, 0.25]]))
    with pytest.raises(Exception, match="more than a model holds"):
        m.to_octree()
    m.write(tmp_path / "wide.tess")
    back = t.OccupancyMap.read(tmp_path / "wide.tess")
    assert back.stats()["occupied"] == m.stats()["occupied"]
    assert back.stats()["free"] == m.stats()["free"]
    cells = m.cells_of(np.array([[1.5e6 + 3.0, 0.25, 0.25], [1.5e6 + 1.0, 0.25, 0.25], [0.0, 0.0, 0.0]]))
    assert np.array_equal(back.log_odds(cells), m.log_odds(cells), equal_nan=True)
    assert list(back.state(cells)) == list(m.state(cells))
    # Read as an octree, it says what it is and what reads it.
    with pytest.raises(Exception, match="OccupancyMap.read"):
        t.Octree.read(tmp_path / "wide.tess")
    # A map that fits an octree reads back from any octree file.
    near = t.OccupancyMap(0.1)
    near.insert_scans(_room_scans())
    near.write(tmp_path / "near.ot")
    assert t.OccupancyMap.read(tmp_path / "near.ot").stats()["occupied"] == near.stats()["occupied"]
    with pytest.raises(FileNotFoundError):
        t.OccupancyMap.read(tmp_path / "missing.tess")
