"""The geometric predicates of relation extraction, shared by every stage that checks relations.

Pure functions over NumPy arrays: distance labels, support-ray grids and parent choice, the
visibility sweep's pieces and per-target visibility.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, TypeVar, cast

import numpy as np
from numpy.typing import ArrayLike

from .boxes import footprint_corners, rotation

DISTANCES = ("adjacent", "proximal", "distant")
T = TypeVar("T")


@dataclass(frozen=True)
class DistanceBands:
    """Extraction's distance labels (``extract.distance``, paper section 4.3): a gap is adjacent up to the smaller of
    ``adjacent_abs`` m and ``adjacent_rel`` of the larger footprint diagonal, proximal up to the larger of
    ``proximal_abs`` m and ``proximal_rel`` of it, distant beyond."""
    adjacent_abs: float
    adjacent_rel: float
    proximal_abs: float
    proximal_rel: float

    @classmethod
    def of(cls, cfg: Mapping[str, Any]) -> "DistanceBands":
        """From the config's ``extract.distance`` section."""
        return cls(**{k: float(v) for k, v in cfg.items()})


def distance_thresholds(max_diag: ArrayLike, bands: DistanceBands) -> tuple[np.ndarray, np.ndarray]:
    """The largest gaps (m) labelled adjacent and proximal (:func:`distance_labels`) between objects whose larger
    footprint diagonal is ``max_diag`` (scalar or array; the result broadcasts alike)."""
    max_diag = np.asarray(max_diag, float)
    return (np.minimum(bands.adjacent_abs, bands.adjacent_rel * max_diag),
            np.maximum(bands.proximal_abs, bands.proximal_rel * max_diag))


def distance_labels(gap: ArrayLike, max_diag: ArrayLike, bands: DistanceBands) -> np.ndarray:
    """adjacent / proximal / distant for gaps (m) between objects whose larger footprint diagonal is ``max_diag``.

    adjacent: gap <= min(adjacent_abs, adjacent_rel * max_diag); proximal: gap <= max(proximal_abs,
    proximal_rel * max_diag); distant otherwise (paper §4.3).
    """
    gap, max_diag = np.broadcast_arrays(np.asarray(gap, float), np.asarray(max_diag, float))
    adj, prox = distance_thresholds(max_diag, bands)
    return np.where(gap <= adj, "adjacent", np.where(gap <= prox, "proximal", "distant"))


# ------------------------------------------------------------------------------------------- support
def support_rays(boxes: np.ndarray, grid: int, start_offset: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Downward rays from a ``grid x grid`` lattice of cell centres under each box.

    Returns ``origins (n*g*g, 3)``, ``directions``, ``obj (n*g*g,)`` (the box each ray belongs to) and
    ``cell_area (n,)`` in m^2.
    """
    b = np.asarray(boxes, float).reshape(-1, 7)
    n = len(b)
    u = (np.arange(grid) + 0.5) / grid * 2.0 - 1.0  # cell centres in [-1, 1]
    gx, gy = np.meshgrid(u, u, indexing="ij")
    local = np.stack([gx.ravel(), gy.ravel()], 1)  # (g*g, 2)
    xy = local[None] * b[:, None, 3:5]  # scale by half extents
    world = np.einsum("nij,nkj->nki", rotation(b[:, 6]), xy) + b[:, None, 0:2]
    z = (b[:, 2] - b[:, 5] + start_offset)[:, None].repeat(grid * grid, 1)
    origins = np.concatenate([world, z[..., None]], axis=2).reshape(-1, 3)
    directions = np.tile([0.0, 0.0, -1.0], (len(origins), 1))
    obj = np.repeat(np.arange(n), grid * grid)
    cell_area = (2 * b[:, 3]) * (2 * b[:, 4]) / (grid * grid)
    return origins, directions, obj, cell_area


def choose_parents(obj: np.ndarray, hit_owner: np.ndarray, hit_dist: np.ndarray, cell_area: np.ndarray,
                   reach: float, size: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Parent per object: the object under it with the largest supporting area within ``reach``.

    ``obj``/``hit_owner``/``hit_dist`` are per ray (nearest hit other than the ray's own object, -1 / inf if
    none). Ties go to the larger object (``size``). Returns ``parent (n,)`` (-1: floor) and ``area (n,)`` m^2.
    """
    n = len(cell_area)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0)
    ok = (hit_owner >= 0) & (hit_dist <= reach)
    counts = np.zeros((n, n))
    np.add.at(counts, (obj[ok], hit_owner[ok]), 1.0)
    score = counts + 1e-9 * (counts > 0) * size[None, :] / max(float(size.max()), 1e-12)
    parent = np.where(counts.max(axis=1) > 0, score.argmax(axis=1), -1)
    area = np.where(parent >= 0, counts[np.arange(n), np.maximum(parent, 0)] * cell_area, 0.0)
    return parent, area


def in_footprint(points: np.ndarray, b: np.ndarray, inset: tuple[float, float] = (0.0, 0.0),
                 least: float = 0.0) -> np.ndarray:
    """Whether plan points ``(..., 2)`` (or wider: x, y first) lie inside the footprints of oriented boxes
    ``(..., 7)`` (broadcast against each other), each shrunk by ``inset`` (x, y) m in its own frame with every half
    extent kept >= ``least`` m (a negative inset grows it)."""
    rel = points[..., :2] - b[..., :2]
    c, s = np.cos(b[..., 6]), np.sin(b[..., 6])
    lx, ly = rel[..., 0] * c + rel[..., 1] * s, -rel[..., 0] * s + rel[..., 1] * c
    half = np.maximum(b[..., 3:5] - np.asarray(inset, float), least)
    return cast(np.ndarray, (np.abs(lx) <= half[..., 0]) & (np.abs(ly) <= half[..., 1]))


def _in_box(points: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Whether points ``(..., 3)`` lie inside oriented boxes ``(..., 7)`` (broadcast against each other)."""
    return cast(np.ndarray, in_footprint(points, b) & (np.abs(points[..., 2] - b[..., 2]) <= b[..., 5]))


def box_containment(points: np.ndarray, boxes: np.ndarray, own: np.ndarray,
                    eligible: np.ndarray | None = None) -> np.ndarray:
    """``(k, n)`` bool: which boxes contain each point, never the point's ``own`` box and, with ``eligible (n,)``,
    only those boxes (box-only models: a meshed model's box is no surface). ``points (k, 3)``, ``boxes (n, 7)``."""
    p, b = np.asarray(points, float).reshape(-1, 3), np.asarray(boxes, float).reshape(-1, 7)
    inside = _in_box(p[:, None, :], b[None, :, :])
    inside[np.arange(len(p)), own] = False
    if eligible is not None:
        inside &= np.asarray(eligible, bool)[None, :]
    return inside


def inside_boxes(points: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """``(k,)`` bool: whether each point ``(k, 3)`` lies inside its own box ``(k, 7)`` (pairwise, not all pairs)."""
    return _in_box(np.asarray(points, float).reshape(-1, 3), np.asarray(boxes, float).reshape(-1, 7))


def holding_box(boxes: np.ndarray, candidates: np.ndarray, eligible: np.ndarray | None = None) -> np.ndarray:
    """For each candidate box, the box that holds it from around: its footprint contains the candidate's
    centre and its vertical span starts above the candidate's bottom and overlaps it (a sink hung in a
    counter slab, a ladle through a holder). The lowest such box wins; -1 where none."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    bottom = b[:, 2] - b[:, 5]
    out = np.full(len(candidates), -1, dtype=np.int64)
    for i, k in enumerate(candidates):
        k_bottom, k_top = b[k, 2] - b[k, 5], b[k, 2] + b[k, 5]
        ok = in_footprint(b[k, None, :2], b) & (bottom > k_bottom) & (bottom < k_top)
        ok[k] = False
        if eligible is not None:
            ok &= np.asarray(eligible, bool)
        if ok.any():
            out[i] = int(np.flatnonzero(ok)[np.argmin(bottom[ok])])
    return out


def hanging(boxes: np.ndarray, parent: np.ndarray, floor_contact: float, min_height: float) -> np.ndarray:
    """``(n,)`` bool: objects that hang (pendant lamps, wall-mounted things): no support parent, nothing resting
    on them, and a bottom more than ``min_height`` above the floor (and above ``floor_contact``)."""
    b = np.asarray(boxes, float).reshape(-1, 7)
    bottom = b[:, 2] - b[:, 5]
    is_parent = np.zeros(len(b), bool)
    is_parent[parent[parent >= 0]] = True
    return cast(np.ndarray, (parent < 0) & ~is_parent & (bottom > max(min_height, floor_contact)))


def parent_cycles(parent: Mapping[T, T | None]) -> list[list[T]]:
    """The cycles of a parent map (node -> its one parent, None for none; a parent missing from the map counts as
    none), each listed child to parent from where walks from the nodes, in the map's order, first meet it.
    ``tests/test_extraction.py`` checks them against networkx's ``simple_cycles``."""
    cycles: list[list[T]] = []
    done: set[T] = set()
    for start in parent:
        path: dict[T, int] = {}
        node: T | None = start
        while node is not None and node not in done and node not in path:
            path[node] = len(path)
            node = parent.get(node)
        if node is not None and node in path:  # the walk closed a cycle
            cycles.append(list(path)[path[node]:])
        done.update(path)
    return cycles


def break_support_cycles(parent: np.ndarray, size: np.ndarray) -> tuple[np.ndarray, list[list[int]]]:
    """Un-parent the largest object of every support cycle (``parent (n,)``, -1 for none; ``size (n,)``; among
    equals the first in the cycle's order). Returns the new parents and the cycles found."""
    cycles = parent_cycles({k: (p if p >= 0 else None) for k, p in enumerate(parent.tolist())})
    out = parent.copy()
    for cycle in cycles:
        out[max(cycle, key=lambda k: size[k])] = -1
    return out, cycles


def tiers(parent: np.ndarray) -> np.ndarray:
    """1 for objects on the floor, 1 + the parent's tier otherwise (parents must be acyclic)."""
    tier = np.zeros(len(parent), dtype=np.int32)

    def depth(k: int) -> int:
        if tier[k] == 0:
            tier[k] = 1 if parent[k] < 0 else depth(parent[k]) + 1
        return int(tier[k])

    for k in range(len(parent)):
        depth(k)
    return tier


# ------------------------------------------------------------------------------------------- visibility
def strip_clearance(corners: np.ndarray, centre: np.ndarray, tangent: np.ndarray, normal: np.ndarray,
                    lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Clearance from an anchor side to a convex footprint within a strip of the side: the smallest distance along
    the side's ``normal``, from the side's line, over the part of the footprint whose position along ``tangent``
    lies in ``[lo, hi]`` (negative where the footprint reaches behind the side: overlap; 0 when flush; inf where
    it misses the strip). Exact for any yaw: see :func:`strip_span`. Returns ``(p,)``."""
    return strip_span(corners, centre, tangent, normal, lo, hi)[0]


def strip_span(corners: np.ndarray, centre: np.ndarray, tangent: np.ndarray, normal: np.ndarray,
               lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The nearest and farthest reach of a convex footprint along a side's normal within a strip of the side
    (``inf, -inf`` where it misses the strip). Exact for any yaw: the extremes lie at a corner inside the strip or
    where an edge crosses a strip boundary.

    ``corners (p, k, 2)`` counter-clockwise convex outlines; ``centre``, ``tangent``, ``normal`` ``(p, 2)`` a point
    of each side's line and its unit axes; ``lo``, ``hi`` ``(p,)`` the strip along the tangent. Returns two ``(p,)``.
    """
    rel = np.asarray(corners, float) - np.asarray(centre, float)[:, None, :]
    t = np.einsum("pkj,pj->pk", rel, tangent)
    d = np.einsum("pkj,pj->pk", rel, normal)
    lo, hi = np.asarray(lo, float)[:, None], np.asarray(hi, float)[:, None]
    inside = (t >= lo) & (t <= hi)
    near, far = np.where(inside, d, np.inf), np.where(inside, d, -np.inf)
    t2, d2 = np.roll(t, -1, axis=1), np.roll(d, -1, axis=1)
    span = np.where(t2 != t, t2 - t, 1.0)
    for bound in (lo, hi):
        crosses = ((t - bound) * (t2 - bound) <= 0) & (t2 != t)
        at = d + (bound - t) / span * (d2 - d)
        near = np.minimum(near, np.where(crosses, at, np.inf))
        far = np.maximum(far, np.where(crosses, at, -np.inf))
    return near.min(axis=1), far.max(axis=1)


def piece_rays(starts: np.ndarray, ends: np.ndarray, inset: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """Two ray positions per piece, ``inset`` in from its ends (one at the middle for tiny pieces).

    Returns ``positions (2p,)`` along the tangent and ``piece (2p,)`` indices.
    """
    length = ends - starts
    a = np.where(length > 2 * inset, starts + inset, (starts + ends) / 2)
    b = np.where(length > 2 * inset, ends - inset, (starts + ends) / 2)
    return np.stack([a, b], 1).ravel(), np.repeat(np.arange(len(starts)), 2)


def footprints(boxes: np.ndarray) -> np.ndarray:
    b = np.asarray(boxes, float).reshape(-1, 7)
    return footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6])
