"""Infinigen's geometric scores as pure functions over arrays (paper section 3.2, appendix A), each with a closed form
on simple cases (``tests/test_solver.py``): angle alignment, rotational and reflection asymmetry (matched with the
Jonker-Volgenant assignment, SciPy's ``linear_sum_assignment``) and the accessibility of an object's front."""
from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment


def alignment_cost(yaw: np.ndarray, reference: np.ndarray, period: float = 2 * np.pi) -> float:
    """Infinigen's angle alignment: the sum over objects of ``(1 - cos theta) / 2``, ``theta`` the angle from each
    ``yaw (n,)`` to its ``reference (n,)`` measured with the given period (``pi / 2``: any wall axis)."""
    theta = (np.asarray(yaw, float) - np.asarray(reference, float)) * (2 * np.pi / period)
    return float(np.sum((1 - np.cos(theta)) / 2))


def _matched_cost(points: np.ndarray, yaws: np.ndarray, moved: np.ndarray, moved_yaws: np.ndarray) -> float:
    """Mean cost of the best one-to-one matching of the moved set onto the set: distance (m) plus the alignment of
    the matched facings."""
    dist = np.linalg.norm(moved[:, None] - points[None], axis=-1)
    cost = dist + (1 - np.cos(moved_yaws[:, None] - yaws[None])) / 2
    rows, cols = linear_sum_assignment(cost)
    return float(cost[rows, cols].mean())


def rotational_asymmetry(points: np.ndarray, yaws: np.ndarray, centre: np.ndarray) -> float:
    """How far ``n`` objects ``points (n, 2)``, ``yaws (n,)`` are from being the same after a turn of ``2 pi / n``
    about ``centre (2,)``: 0 for e.g. four chairs at a square's corners facing its centre."""
    n = len(points)
    if n < 2:
        return 0.0
    a = 2 * np.pi / n
    r = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    moved = (np.asarray(points, float) - centre) @ r.T + centre
    return _matched_cost(np.asarray(points, float), np.asarray(yaws, float), moved, np.asarray(yaws, float) + a)


def reflection_asymmetry(points: np.ndarray, yaws: np.ndarray, origin: np.ndarray, axis: np.ndarray) -> float:
    """How far the objects are from their mirror image in the line through ``origin (2,)`` along ``axis (2,)``:
    0 for a mirror pair (two nightstands either side of a bed's centre line)."""
    if len(points) == 0:
        return 0.0
    u = np.asarray(axis, float) / np.linalg.norm(axis)
    rel = np.asarray(points, float) - origin
    mirrored = 2 * (rel @ u)[:, None] * u - rel + origin
    phi = np.arctan2(u[1], u[0])
    # a facing f (the local +y turned by yaw) reflects to 2 phi - f, so the yaw reflects to 2 phi - yaw - pi
    return _matched_cost(np.asarray(points, float), np.asarray(yaws, float), mirrored,
                         2 * phi - np.asarray(yaws, float) - np.pi)


def accessibility_cost(front: np.ndarray, normal: np.ndarray, others: np.ndarray, diagonals: np.ndarray,
                       reach: float) -> float:
    """Infinigen's accessibility of one object's front: the sum over other objects ``b`` in front of it, within
    ``reach`` m, of ``((b - a) . n / |b - a|^2) |diag(b)|``; ``front (2,)``: the front face's midpoint ``a``,
    ``normal (2,)`` its outward unit normal ``n``, ``others (m, 2)`` centres, ``diagonals (m,)`` footprint
    diagonals (m). A blocker of diagonal ``g`` straight ahead at distance ``d`` costs ``g / d``."""
    if len(others) == 0:
        return 0.0
    rel = np.asarray(others, float) - front
    ahead = rel @ normal
    dist2 = np.maximum(np.einsum("ij,ij->i", rel, rel), 1e-6)
    near = (ahead > 0) & (dist2 <= reach ** 2)
    return float(np.sum(np.where(near, ahead / dist2 * diagonals, 0.0)))
