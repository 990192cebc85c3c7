"""GRAINS's relative-position code (Li et al. 2019, section 3.2): where box ``b`` stands relative to box ``a``.

Boxes are ``(cx, cy, cz, hx, hy, hz, yaw)`` (:mod:`pipeline.geometry.boxes`); the code is 2D (height is left to
the hierarchy: siblings share a base, a supported child stands on its parent's top). Everything is measured in
``a``'s local frame (x right, y front). Layout of the ``(28,)`` code:

- ``[0]`` rotation: ``wrap(yaw_b - yaw_a) / pi`` in ``[-1, 1)``.
- ``[1]`` x offset, ``[2]`` y offset (m). ``b``'s footprint extents in ``a``'s frame are
  ``(ex, ey) = |R(yaw_b - yaw_a)| @ half_b[:2]`` (the half sizes of its axis-aligned bound there), so ``b``'s
  edges in ``a``'s frame are ``left = dx - ex``, ``right = dx + ex``, ``back = dy - ey``, ``front = dy + ey``
  (``(dx, dy)``: ``b``'s centre in ``a``'s frame; "b's left" is the bound's smaller-x side, not ``b``'s own
  local left once it is turned). For x, of the four pairs (``a``'s edge in {left, right}, ``b``'s edge in
  {left, right}) the one with the smallest ``|b edge - a edge|`` is kept and ``b edge - a edge`` stored; likewise
  for y with {front, back}. Ties go to the first pair in :data:`SIDES` order.
- ``[3:19]`` two-hot: bit ``3 + a_edge_x * 4 + b_edge_x`` and bit ``3 + a_edge_y * 4 + b_edge_y`` (indices into
  :data:`SIDES`): the x pair always falls in ``{10, 11, 14, 15} + 3``, the y pair in ``{0, 1, 4, 5} + 3``.
- ``[19:23]`` attachment, one bit per side ``k`` of ``a`` in :data:`SIDES` order: ``b``'s bound lies within
  ``eps`` of that side's line (a gap or an overlap of at most ``eps``) and overlaps the side's span.
- ``[23:28]`` alignment: centre x equal, centre y equal (``|dx|``, ``|dy| <= eps``), same yaw (mod 2 pi, within
  1 degree), front edges collinear, back edges collinear (the same yaw, so the two fronts face one way, and
  ``b``'s edge on ``a``'s edge line within ``eps``; a box turned half a turn whose front meets ``a``'s front is a
  contact, the attachment bits' business, not an alignment).

:func:`decode` inverts :func:`encode` exactly for the centre and yaw given ``a`` and ``b``'s true half extents: the
rotation gives ``(ex, ey)``, the edge pairs and offsets give ``b``'s edges and so its centre. Numpy only.
"""
from __future__ import annotations

import math

import numpy as np

from ...geometry.boxes import rotation
from ...geometry.frames import wrap

CODE = 28
SIDES = ("front", "back", "left", "right")   # local +y, -y, -x, +x
ROT, OFF_X, OFF_Y = 0, 1, 2
PAIRS = slice(3, 19)
ATTACH = slice(19, 23)
ALIGN = slice(23, 28)
ALIGN_NAMES = ("centre_x", "centre_y", "yaw", "front", "back")
SAME_YAW = ALIGN.start + ALIGN_NAMES.index("yaw")  # the same-yaw bit's index in a code
YAW_TOL = math.radians(1.0)
X_EDGES, Y_EDGES = (2, 3), (0, 1)  # SIDES indices of left/right and front/back
_SIGN = {0: 1.0, 1: -1.0, 2: -1.0, 3: 1.0}  # the side's direction along its axis


def extents(rot: float, half: np.ndarray) -> np.ndarray:
    """``(2,)`` half sizes (m) of the bound, in a frame turned ``rot`` (rad) from the box's, of a box of ``half``."""
    return np.abs(rotation(rot)) @ np.asarray(half, float)[:2]


def relative(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float]:
    """``b``'s centre ``(2,)`` in ``a``'s frame (m) and its yaw relative to ``a`` (rad, wrapped)."""
    d = rotation(float(a[6])).T @ (np.asarray(b[:2], float) - np.asarray(a[:2], float))
    return d, float(wrap(float(b[6]) - float(a[6])))


def _best_pair(centre: float, ext: float, half_a: float, edges: tuple[int, int]) -> tuple[int, int, float]:
    """The (a edge, b edge, signed offset) of the closest edge pair along one axis."""
    best = None
    for ea in edges:
        for eb in edges:
            off = (centre + _SIGN[eb] * ext) - _SIGN[ea] * half_a
            if best is None or abs(off) < abs(best[2]):
                best = (ea, eb, off)
    return best


def attachment(d: np.ndarray, ext: np.ndarray, half_a: np.ndarray, eps: float) -> np.ndarray:
    """``(4,)`` 0/1: ``b``'s bound (centre ``d``, half sizes ``ext``) touches ``a``'s side k within ``eps``."""
    out = np.zeros(4)
    for k, axis in ((0, 1), (1, 1), (2, 0), (3, 0)):
        other = 1 - axis
        gap = _SIGN[k] * d[axis] - ext[axis] - half_a[axis]
        spans = abs(d[other]) < half_a[other] + ext[other]
        out[k] = float(abs(gap) <= eps and spans)
    return out


def alignment(d: np.ndarray, rot: float, half_a: np.ndarray, half_b: np.ndarray, eps: float) -> np.ndarray:
    """``(5,)`` 0/1: centre x, centre y, yaw, front edges collinear, back edges collinear (m, rad)."""
    same = abs(rot) <= YAW_TOL
    front, back = d[1] + half_b[1], d[1] - half_b[1]
    return np.array([abs(d[0]) <= eps, abs(d[1]) <= eps, same,
                     same and abs(front - half_a[1]) <= eps, same and abs(back + half_a[1]) <= eps], float)


def encode(a: np.ndarray, b: np.ndarray, eps: float = 0.01) -> np.ndarray:
    """(28,) code of box b (7,) relative to box a (7,); ``eps`` (m) is the contact and alignment tolerance."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d, rot = relative(a, b)
    ext = extents(rot, b[3:5])
    ax, bx, ox = _best_pair(d[0], ext[0], a[3], X_EDGES)
    ay, by, oy = _best_pair(d[1], ext[1], a[4], Y_EDGES)
    code = np.zeros(CODE)
    code[ROT], code[OFF_X], code[OFF_Y] = rot / math.pi, ox, oy
    code[3 + ax * 4 + bx] = 1.0
    code[3 + ay * 4 + by] = 1.0
    code[ATTACH] = attachment(d, ext, a[3:5], eps)
    code[ALIGN] = alignment(d, rot, a[3:5], b[3:5], eps)
    return code


def edge_pair(code: np.ndarray, edges: tuple[int, int]) -> tuple[int, int]:
    """The (a edge, b edge) ``SIDES`` indices of the largest two-hot entry among one axis's four pairs."""
    cands = [(ea, eb) for ea in edges for eb in edges]
    scores = [code[3 + ea * 4 + eb] for ea, eb in cands]
    return cands[int(np.argmax(scores))]


def snapped(code: np.ndarray, d: np.ndarray, ext: np.ndarray, half_a: np.ndarray, half_b: np.ndarray) -> np.ndarray:
    """``b``'s centre ``d`` (2,) in ``a``'s frame moved onto what the code's bits state (bits > 0.5): centres
    aligned, fronts or backs collinear (with the same yaw), then a contact with one side of ``a`` (the bound's
    edge on that side's line, outside it), which wins on its axis. ``ext``: the bound's half sizes (m)."""
    al, at = np.asarray(code[ALIGN]) > 0.5, np.asarray(code[ATTACH]) > 0.5
    d = np.array(d, float)
    d[0] = 0.0 if al[0] else d[0]
    d[1] = 0.0 if al[1] else d[1]
    if al[2] and al[3] != al[4]:
        d[1] = (half_a[1] - half_b[1]) if al[3] else (half_b[1] - half_a[1])
    if at[0] != at[1]:
        d[1] = (half_a[1] + ext[1]) * (1.0 if at[0] else -1.0)
    if at[2] != at[3]:
        d[0] = (half_a[0] + ext[0]) * (-1.0 if at[2] else 1.0)
    return d


def decode(a: np.ndarray, half_b: np.ndarray, code: np.ndarray, snap: bool = False) -> tuple[float, float, float]:
    """b's centre x, y and yaw given a (7,), b's half extents (3,) and a code (28,) (a decoded code may be soft:
    use argmax of each one-hot group: the x pair among its four entries, the y pair among its four).

    ``snap``: a decoded code's reals are regressed, its bits classified; with ``snap`` the bits win (the same-yaw
    bit sets the rotation to 0, then :func:`snapped`), as the bits exist to state exact contacts and alignments.
    The yaw comes back wrapped into ``[-pi, pi)``; metres and radians.
    """
    a, code = np.asarray(a, float), np.asarray(code, float)
    rot = 0.0 if snap and code[SAME_YAW] > 0.5 else float(code[ROT]) * math.pi
    ext = extents(rot, half_b)
    ax, bx = edge_pair(code, X_EDGES)
    ay, by = edge_pair(code, Y_EDGES)
    dx = _SIGN[ax] * a[3] + code[OFF_X] - _SIGN[bx] * ext[0]
    dy = _SIGN[ay] * a[4] + code[OFF_Y] - _SIGN[by] * ext[1]
    if snap:
        dx, dy = snapped(code, np.array([dx, dy]), ext, a[3:5], np.asarray(half_b, float))
    c = a[:2] + rotation(float(a[6])) @ np.array([dx, dy])
    return float(c[0]), float(c[1]), float(wrap(float(a[6]) + rot))
