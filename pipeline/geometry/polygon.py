"""Floor outlines and wall loops.

Polygons are ``(n, 2) float`` arrays of vertices, not repeated at the end. Wall segments are
``(m, 2, 2) float`` arrays: ``segments[i] = [[x0, y0], [x1, y1]]``.
"""
from __future__ import annotations

from typing import cast

import numpy as np


def signed_area(xy: np.ndarray) -> float:
    """Shoelace area: positive when the vertices run counter-clockwise."""
    xy = np.asarray(xy, dtype=float)
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def make_ccw(xy: np.ndarray) -> np.ndarray:
    """The same outline, counter-clockwise."""
    xy = np.asarray(xy, dtype=float)
    return xy[::-1].copy() if signed_area(xy) < 0 else xy.copy()


def merge_collinear(xy: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """Drop vertices whose two edges are collinear (and repeated vertices)."""
    xy = np.asarray(xy, dtype=float)
    changed = True
    while changed and len(xy) > 3:
        changed = False
        prev, nxt = np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0)
        a, b = xy - prev, nxt - xy
        cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        scale = np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1)
        dot = np.einsum("ij,ij->i", a, b)
        drop = (np.abs(cross) <= tol * np.maximum(scale, tol)) & (dot >= 0)
        drop |= np.linalg.norm(a, axis=1) <= tol
        if drop.any():
            # drop one vertex at a time so neighbouring decisions stay valid
            xy = np.delete(xy, int(np.argmax(drop)), axis=0)
            changed = True
    return xy


def polygon_segments(xy: np.ndarray) -> np.ndarray:
    """``(n, 2, 2)`` segments of a closed outline, in vertex order."""
    xy = np.asarray(xy, dtype=float)
    return np.stack([xy, np.roll(xy, -1, axis=0)], axis=1)


def segment_distances(point: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """``(..., m)`` distance from each ``(..., 2)`` point to each of ``(m, 2, 2)`` segments (to its nearest point)."""
    p = np.asarray(point, float)[..., None, :]
    a, d = segments[:, 0], segments[:, 1] - segments[:, 0]
    length2 = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.einsum("...ij,ij->...i", p - a, d) / np.maximum(length2, 1e-18), 0.0, 1.0)
    return cast(np.ndarray, np.linalg.norm(a + t[..., None] * d - p, axis=-1))


def nearest_segment(point: np.ndarray, segments: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For ``(..., 2)`` points: the distance to the nearest of ``(m, 2, 2)`` segments and its index (``(...)``
    each; the first of equals)."""
    dist = segment_distances(point, segments)
    return dist.min(-1), dist.argmin(-1)


def segment_interval(points: np.ndarray, segment: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """End points of the stretch of ``segment`` ((2, 2)) that ``(k, 2)`` points project onto, clipped to it."""
    a, d = segment[0], segment[1] - segment[0]
    length = float(np.linalg.norm(d))
    u = d / length
    t = np.clip((np.asarray(points, float) - a) @ u, 0.0, length)
    return a + u * t.min(), a + u * t.max()


def inward_normals(segments: np.ndarray) -> np.ndarray:
    """Unit normals pointing into the room for counter-clockwise wall segments (left of travel)."""
    d = segments[:, 1] - segments[:, 0]
    d = d / np.linalg.norm(d, axis=1, keepdims=True)
    return np.stack([-d[:, 1], d[:, 0]], axis=1)


def wall_loop(segments: np.ndarray, tol: float = 1e-3) -> tuple[bool, str, np.ndarray]:
    """Check that wall segments form one closed loop.

    Rule (authors' code): more than two walls, every endpoint meets exactly one endpoint of another
    wall within ``tol``, and a single loop runs through all walls.

    Returns ``(closed, reason, order)``: ``order`` lists wall indices along the loop, each wall
    oriented so that it starts where the previous one ended (``reason`` is '' when closed).
    """
    segs = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    n = len(segs)
    if n < 3:
        return False, f"only {n} wall(s)", np.arange(n)
    ends = segs.reshape(-1, 2)  # 2n endpoints: 2i start, 2i+1 end of wall i
    dist = np.linalg.norm(ends[:, None, :] - ends[None, :, :], axis=2)
    np.fill_diagonal(dist, np.inf)
    own = np.arange(2 * n) // 2
    dist[own[:, None] == own[None, :]] = np.inf
    match = dist <= tol
    counts = match.sum(axis=1)
    if (counts != 1).any():
        bad = int(np.flatnonzero(counts != 1)[0])
        what = "meets no other wall" if counts[bad] == 0 else f"meets {counts[bad]} walls"
        return False, f"wall {bad // 2} {'start' if bad % 2 == 0 else 'end'} {what}", np.arange(n)
    partner = np.argmax(match, axis=1)
    order, visited = [0], {0}
    at = 1  # leave wall 0 through its end
    for _ in range(n - 1):
        nxt_end = int(partner[at])
        wall = nxt_end // 2
        if wall in visited:
            return False, f"walls form more than one loop ({len(visited)} of {n} in the first)", np.arange(n)
        visited.add(wall)
        order.append(wall if nxt_end % 2 == 0 else -wall - 1)
        at = nxt_end ^ 1
    if partner[at] // 2 != 0:
        return False, "wall loop does not return to its first wall", np.arange(n)
    return True, "", np.array(order)


def outline_from_loop(segments: np.ndarray, order: np.ndarray) -> np.ndarray:
    """Vertices of the closed loop given by :func:`wall_loop`'s ``order`` (negative = reversed wall)."""
    pts = []
    for o in order:
        seg = segments[o] if o >= 0 else segments[-o - 1][::-1]
        pts.append(seg[0])
    return np.asarray(pts)


def extents(xy: np.ndarray) -> tuple[float, float]:
    """Axis-aligned extents (x, y) of an outline."""
    xy = np.asarray(xy, dtype=float)
    span = xy.max(axis=0) - xy.min(axis=0)
    return float(span[0]), float(span[1])


def poke_out(outline: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``(n,)`` how far (m) each of ``points (n, 2)`` lies outside the polygon ``outline (k, 2)`` (0 inside)."""
    import shapely

    poly = shapely.Polygon(outline)
    pts = shapely.points(np.asarray(points, float).reshape(-1, 2))
    return np.where(shapely.covers(poly, pts), 0.0, shapely.distance(poly.exterior, pts))


def outside_area(outline: np.ndarray, corners: np.ndarray, erode: float) -> np.ndarray:
    """``(n,)`` m^2 of each footprint ``corners (n, 4, 2)``, eroded by ``erode`` m (mitred), that lies outside the
    polygon ``outline (k, 2)``. Unlike a test of the corners, it sees a reflex wall corner that pierces a footprint
    whose corners all stand on the floor."""
    import shapely

    eroded = shapely.buffer(shapely.polygons(np.asarray(corners, float)), -erode, join_style="mitre")
    return cast(np.ndarray, shapely.area(shapely.difference(eroded, shapely.Polygon(outline))))


RECT_FILL = 0.99  # a part of a rectangle outside a room counts as a rectangle when it fills this share of its envelope


def outside_pieces(outline: np.ndarray, rect: tuple[float, float, float, float]) -> np.ndarray:
    """``(m, 4, 2)`` corners of the parts of ``rect = (xmin, ymin, xmax, ymax)`` (m) that lie outside the polygon
    ``outline (k, 2)`` and are rectangles (each fills :data:`RECT_FILL` of its oriented envelope): an L-shaped room's
    missing corner; none for a room that fills its rectangle. A part that is no rectangle (the triangle a slanted wall
    leaves, the notch of a room with a stepped side, a floating-point sliver) is left out: its envelope would reach
    into the room."""
    import shapely

    rest = shapely.box(*rect).difference(shapely.Polygon(outline))
    parts = [g for g in getattr(rest, "geoms", [rest]) if g.area > 1e-6]
    envelopes = [shapely.oriented_envelope(g) for g in parts]
    return np.array([np.asarray(e.exterior.coords)[:4] for g, e in zip(parts, envelopes) if g.area >= RECT_FILL * e.area],
                    float).reshape(-1, 4, 2)


def door_zones(outline: np.ndarray, doors: np.ndarray, depth: float) -> np.ndarray:
    """``(m, 4, 2)`` counter-clockwise rectangles reaching ``depth`` m into the room from each door segment of
    ``doors (m, 2, 2)`` (the side whose point just off the door's midpoint lies inside ``outline (k, 2)``)."""
    doors = np.asarray(doors, float).reshape(-1, 2, 2)
    a, b = doors[:, 0], doors[:, 1]
    d = b - a
    n = np.stack([-d[:, 1], d[:, 0]], 1) / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    probe = (a + b) / 2 + 0.05 * n
    n = np.where((poke_out(outline, probe) > 0)[:, None], -n, n)  # flip where the left side is outside
    quads = np.stack([a, b, b + depth * n, a + depth * n], axis=1)
    u, v = quads[:, 1] - quads[:, 0], quads[:, 2] - quads[:, 1]
    ccw = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0] > 0
    return np.where(ccw[:, None, None], quads, quads[:, ::-1])
