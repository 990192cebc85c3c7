"""Top-down rasters (geometry/raster.py): against shapely on random turned boxes, polygons that are not
rectangles, overlaps and rooms larger than the window."""
import math

import numpy as np
import pytest
import shapely
from hypothesis import given, strategies as st

from pipeline.geometry import raster
from pipeline.geometry.boxes import footprint_corners
from pipeline.geometry.polygon import polygon_segments

L_ROOM = np.array([[0, 0], [5, 0], [5, 4], [2, 4], [2, 3], [0, 3.0]])


def centres_inside(poly, size, mpp, centre):
    xs, ys = raster.pixel_centres(size, mpp, centre)
    gx, gy = np.meshgrid(xs, ys)
    return shapely.contains_xy(poly, gx, gy), shapely.distance(poly.exterior, shapely.points(gx, gy))


@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(0.05, 1.5), st.floats(0.05, 1.5), st.floats(-4, 4))
def test_a_turned_box_fills_exactly_the_pixels_whose_centres_it_holds(cx, cy, hx, hy, yaw):
    image = np.zeros((64, 64), np.float32)
    corners = footprint_corners(np.array([cx]), np.array([cy]), np.array([hx]), np.array([hy]), np.array([yaw]))
    raster.fill_quads(image, corners, 1.0, 0.1, (0.0, 0.0))
    inside, dist = centres_inside(shapely.Polygon(corners[0]), 64, 0.1, (0.0, 0.0))
    clear = dist > 1e-6  # pixel centres on the outline may go either way
    assert ((image > 0) == inside)[clear].all()


def test_a_floor_that_is_not_a_rectangle_is_filled_by_its_area():
    floor = raster.fill_polygon(L_ROOM, 128, 0.05, (2.5, 2.0))
    inside, dist = centres_inside(shapely.Polygon(L_ROOM), 128, 0.05, (2.5, 2.0))
    assert (floor == inside)[dist > 1e-6].all()
    assert floor.sum() * 0.05 ** 2 == pytest.approx(shapely.Polygon(L_ROOM).area, rel=0.01)


def test_render_channels_heights_orientation_and_anchor():
    walls = polygon_segments(L_ROOM)
    boxes = np.array([[1.0, 1.0, 0.4, 0.5, 0.5, 0.4, 0.0],  # a table top at 0.8 m
                      [1.0, 1.0, 1.0, 0.1, 0.1, 0.1, math.pi / 2],  # a vase on it, turned, top at 1.1 m
                      [4.0, 1.0, 0.3, 0.3, 0.3, 0.3, math.pi]])
    shell = raster.Shell(L_ROOM, walls, np.full(len(walls), 0.075), {"doors": np.array([[[3.0, 0.0], [3.9, 0.0]]])})
    img = raster.render_room(shell, boxes, np.array([0, 1, 0]), 2, raster.Canvas(64, 0.1, (2.5, 2.0)), anchor=2)
    assert img.shape == (len(raster.CHANNELS) + 2, 64, 64)
    row, col = lambda y: int((2.0 + 3.2 - y) / 0.1), lambda x: int((x - 2.5 + 3.2) / 0.1)  # noqa: E731
    assert img[4, row(1.0), col(1.0)] == pytest.approx(1.1) and img[4, row(1.35), col(1.35)] == pytest.approx(0.8)
    assert img[5, row(1.0), col(1.0)] == pytest.approx(1.0) and img[6, row(1.35), col(1.35)] == pytest.approx(1.0)
    assert img[6, row(1.0), col(4.0)] == pytest.approx(-1.0)  # turned 180 deg
    assert img[7].sum() == img[len(raster.CHANNELS) + 0][:, col(3.0):].sum() > 0  # the anchor alone, at x = 4
    assert img[len(raster.CHANNELS) + 1].sum() == pytest.approx(4, abs=2)  # the 0.2 m vase: about 4 pixels
    assert img[1, row(3.5), col(2.0)] == 1 and img[2, row(0.0), col(3.5)] == 1 and img[3].sum() == 0
    assert img[0, row(3.5), col(1.0)] == 0 and img[0, row(3.5), col(3.5)] == 1  # the L's missing corner


def test_a_room_larger_than_the_window_is_cropped_to_it():
    big = np.array([[0, 0], [12, 0], [12, 9], [0, 9.0]])
    shell = raster.Shell(big, polygon_segments(big), np.full(4, 0.1), {})
    img = raster.render_room(shell, np.zeros((0, 7)), np.zeros(0, int), 1, raster.Canvas(64, 0.1, (6.0, 4.5)))
    assert img[0].all() and not img[1].any()  # all floor, no wall within 3.2 m of the centre
    corner = raster.render_room(shell, np.zeros((0, 7)), np.zeros(0, int), 1, raster.Canvas(64, 0.1, (0.0, 0.0)))
    assert corner[0].mean() == pytest.approx(0.25, abs=0.02) and corner[1].any()


def test_small_and_large_windows_fill_the_same_pixels_in_one_call_as_one_by_one():
    """Windows under raster.FLAT_WINDOW pixels are tested as one flat array, larger ones one by one: a mix in one
    call, turned at odd angles and overlapping, fills exactly what each quad fills alone and what shapely holds."""
    rng = np.random.default_rng(3)
    half = np.concatenate([rng.uniform(0.05, 0.3, (12, 2)), [[2.5, 1.9], [0.02, 2.8]]])  # two windows > 1024 px
    corners = footprint_corners(rng.uniform(-2, 2, 14), rng.uniform(-2, 2, 14), half[:, 0], half[:, 1],
                                rng.uniform(-np.pi, np.pi, 14))
    together = np.zeros((64, 64))
    raster.fill_quads(together, corners, 1.0, 0.1, (0.0, 0.0))
    alone = np.zeros((64, 64))
    for c in corners:
        raster.fill_quads(alone, c[None], 1.0, 0.1, (0.0, 0.0))
    assert np.array_equal(together, alone) and together.sum() > 1500
    inside, dist = centres_inside(shapely.union_all(shapely.polygons(corners)), 64, 0.1, (0.0, 0.0))
    assert ((together > 0) == inside)[dist > 1e-6].all()


def test_a_wall_without_thickness_fills_its_own_length_only():
    """A slab of zero width is a segment: its pixels lie on it (within a pixel of its ends), never on the line
    beyond (where every edge test of the flat quad holds)."""
    seg = np.array([[[-1.0, 0.05], [1.0, 0.05]]])  # along a row of pixel centres
    image = np.zeros((64, 64))
    raster.fill_quads(image, raster.segment_quads(seg, np.zeros(1)), 1.0, 0.1, (0.0, 0.0))
    rows, cols = np.nonzero(image)
    xs, _ = raster.pixel_centres(64, 0.1, (0.0, 0.0))
    assert set(rows) == {31} and 20 <= len(cols) <= 22 and (np.abs(xs[cols]) <= 1.0 + 0.1).all()
