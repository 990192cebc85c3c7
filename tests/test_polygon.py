import math

import numpy as np
import pytest
from hypothesis import given, strategies as st

from pipeline.geometry.frames import wrap
from pipeline.geometry.polygon import (
    extents,
    make_ccw,
    merge_collinear,
    nearest_segment,
    outline_from_loop,
    polygon_segments,
    segment_distances,
    segment_interval,
    signed_area,
    wall_loop,
)

SQUARE = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], float)
L_SHAPE = np.array([[0, 0], [4, 0], [4, 2], [2, 2], [2, 4], [0, 4]], float)


def test_signed_area_and_orientation():
    assert signed_area(SQUARE) == 4.0
    assert signed_area(SQUARE[::-1]) == -4.0
    assert signed_area(make_ccw(SQUARE[::-1])) == 4.0
    assert signed_area(L_SHAPE) == 12.0
    assert extents(L_SHAPE) == (4.0, 4.0)


def test_merge_collinear_removes_midpoints_only():
    with_mid = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [2, 2], [0, 2]], float)
    merged = merge_collinear(with_mid)
    assert len(merged) == 4
    assert set(map(tuple, merged)) == set(map(tuple, SQUARE))
    assert len(merge_collinear(L_SHAPE)) == 6  # a reflex corner is no collinear point


def test_wall_loop_closed_and_open():
    segs = polygon_segments(L_SHAPE)
    ok, why, order = wall_loop(segs)
    assert ok and why == ""
    assert np.isclose(abs(signed_area(outline_from_loop(segs, order))), 12.0)
    gap = segs.copy()
    gap[2, 1] += [0.0, -0.3]  # shorten one wall: the loop no longer closes
    ok, why, _ = wall_loop(gap)
    assert not ok and "meets no other wall" in why
    assert not wall_loop(segs[:2])[0]


def test_two_separate_loops_are_not_one_room():
    a = polygon_segments(SQUARE)
    b = polygon_segments(SQUARE + 10)
    ok, why, _ = wall_loop(np.concatenate([a, b]))
    assert not ok and "more than one loop" in why


@st.composite
def star_polygons(draw):
    """Random simple polygons: sorted angles, random radii (star-shaped, so never self-intersecting)."""
    n = draw(st.integers(3, 12))
    angles = np.sort(np.array(draw(st.lists(st.floats(0, 2 * np.pi - 1e-3), min_size=n, max_size=n, unique=True))))
    if np.min(np.diff(np.concatenate([angles, [angles[0] + 2 * np.pi]]))) < 1e-2:
        angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    radii = np.array(draw(st.lists(st.floats(1.0, 5.0), min_size=n, max_size=n)))
    return np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])


@given(poly=star_polygons(), seed=st.integers(0, 2**31 - 1), cut=st.floats(0.01, 0.5))
def test_wall_loop_properties(poly, seed, cut):
    rng = np.random.default_rng(seed)
    segs = polygon_segments(poly)
    # shuffled and randomly reversed walls still form one closed loop with the same area
    perm = rng.permutation(len(segs))
    flips = rng.random(len(segs)) < 0.5
    shuffled = np.array([s[::-1] if f else s for s, f in zip(segs[perm], flips)])
    ok, _, order = wall_loop(shuffled)
    assert ok
    assert np.isclose(abs(signed_area(outline_from_loop(shuffled, order))), abs(signed_area(poly)))
    assert signed_area(make_ccw(poly)) > 0
    # pulling one endpoint away by more than the tolerance opens the loop
    k = int(rng.integers(len(segs)))
    broken = segs.copy()
    d = broken[k, 1] - broken[k, 0]
    broken[k, 1] -= d / np.linalg.norm(d) * min(cut, 0.5 * np.linalg.norm(d))
    assert not wall_loop(broken, tol=1e-3)[0]
    # dropping a wall opens it too
    assert not wall_loop(np.delete(segs, k, axis=0))[0]


def test_point_to_wall_distance_and_projection():
    segs = np.array([[[0, 0], [4, 0]], [[4, 0], [4, 3]]], float)
    assert segment_distances(np.array([2.0, 0.3]), segs) == pytest.approx([0.3, 2.0])
    # past both walls' ends: the distance to their end points, not to their lines (1 and 4)
    assert segment_distances(np.array([5.0, 4.0]), segs) == pytest.approx([math.hypot(1, 4), math.hypot(1, 1)])
    # a door's corners project onto the stretch they cover, clipped to the wall
    p0, p1 = segment_interval(np.array([[1.0, 0.1], [1.9, -0.1], [5.0, 0.0]]), segs[0])
    assert p0 == pytest.approx([1.0, 0.0]) and p1 == pytest.approx([4.0, 0.0])
    # many points at once: each point's distances, and the nearest wall (the first of equals)
    pts = np.array([[2.0, 0.3], [5.0, 4.0], [4.0, 0.0]])
    assert segment_distances(pts, segs) == pytest.approx(np.stack([segment_distances(p, segs) for p in pts]))
    dist, index = nearest_segment(pts, segs)
    assert dist == pytest.approx([0.3, math.hypot(1, 1), 0.0]) and index.tolist() == [0, 1, 0]


def test_wrap_stays_in_minus_pi_to_pi():
    a = np.array([-np.pi - 1e-17, -np.pi, np.pi, 3 * np.pi, 7.0, -1e-300])
    out = wrap(a)
    assert ((out >= -np.pi) & (out < np.pi)).all()
    assert out[:4] == pytest.approx([-np.pi] * 4) and out[4] == pytest.approx(7.0 - 2 * np.pi)
    assert isinstance(wrap(1.0), np.floating)
