"""Plan frames: an origin, a yaw and an optional mirror, and moving a room's plan geometry into and out of them.

A frame maps world plan points ``q`` to local ones by ``local = M R(-yaw) (q - origin)``, where ``M`` flips x
when ``mirror`` is set. The placement networks see every room in an anchor's frame (origin at the anchor, its front
along +y); a symmetric anchor has several equivalent frames (:func:`equivalent_frames`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .boxes import SIDES

RADIAL_FRAMES = 8  # radial symmetry: this many turns stand for the continuum
# turns under which an object of a symmetry type looks the same from above (its fronts); radial: every turn (0)
FOLD = {"rotational-2": 2, "front-back": 2, "rotational-4": 4, "radial": 0}


def wrap(angle: ArrayLike) -> np.ndarray:
    """Angles (rad) wrapped to [-pi, pi); a remainder that rounds up to 2 pi lands on -pi, not pi."""
    out = (np.asarray(angle, float) + np.pi) % (2 * np.pi) - np.pi
    return out - 2 * np.pi * (out >= np.pi)


def turn_error(angle: ArrayLike, symmetry: ArrayLike = "none") -> np.ndarray:
    """``(...)`` smallest turn (rad, 0..pi) from ``angle`` to a turn an object of ``symmetry`` cannot be told apart
    from (0 for radial): how far a yaw difference, or a front's angle to a direction, is from none, counting the
    equivalent fronts of symmetric objects (a rotational-2 keyboard turned by half a turn faces the same way).
    ``symmetry`` is one type or an array of types broadcast against ``angle``."""
    a = np.asarray(angle, float)
    fold = np.vectorize(lambda s: FOLD.get(s, 1), otypes=[int])(np.asarray(symmetry, object))
    step = 2 * np.pi / np.maximum(fold, 1)
    err = np.abs(wrap(a - np.round(a / step) * step))
    return np.where(fold == 0, 0.0, err)


@dataclass(frozen=True)
class Frame:
    origin: tuple[float, float]
    yaw: float
    mirror: bool = False

    def turned(self, angle: float, mirror: bool = False) -> "Frame":
        """The same origin, turned by ``angle`` (rad) and mirrored about the new local y axis if ``mirror``."""
        return Frame(self.origin, self.yaw + angle, self.mirror != mirror)


def front_of(yaw: ArrayLike) -> np.ndarray:
    """``(..., 2)`` world unit vector an object turned ``yaw (...)`` (rad) faces: its local +y (yaw 0 faces +y)."""
    y = np.asarray(yaw, float)
    return np.stack([-np.sin(y), np.cos(y)], -1)


def to_local(frame: Frame, points: np.ndarray) -> np.ndarray:
    """World ``(..., 2)`` points -> frame coordinates."""
    c, s = np.cos(frame.yaw), np.sin(frame.yaw)
    d = np.asarray(points, float) - frame.origin
    x, y = c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]
    return np.stack([-x if frame.mirror else x, y], -1)


def to_world(frame: Frame, points: np.ndarray) -> np.ndarray:
    """Frame ``(..., 2)`` points -> world coordinates."""
    p = np.asarray(points, float)
    x = -p[..., 0] if frame.mirror else p[..., 0]
    c, s = np.cos(frame.yaw), np.sin(frame.yaw)
    return np.stack([c * x - s * p[..., 1], s * x + c * p[..., 1]], -1) + frame.origin


def yaw_to_local(frame: Frame, yaw: ArrayLike) -> np.ndarray:
    """World yaw -> frame yaw (a mirror reverses the turning sense), wrapped to [-pi, pi)."""
    y = np.asarray(yaw, float) - frame.yaw
    return wrap(-y if frame.mirror else y)


def yaw_to_world(frame: Frame, yaw: ArrayLike) -> np.ndarray:
    y = np.asarray(yaw, float)
    return wrap((-y if frame.mirror else y) + frame.yaw)


def boxes_to_local(frame: Frame, boxes: np.ndarray) -> np.ndarray:
    """``(n, 7)`` boxes (cx, cy, cz, hx, hy, hz, yaw) in the frame."""
    b = np.array(boxes, float).reshape(-1, 7)
    b[:, :2] = to_local(frame, b[:, :2])
    b[:, 6] = yaw_to_local(frame, b[:, 6])
    return b


def equivalent_frames(frame: Frame, symmetry: str) -> list[Frame]:
    """The anchor's frames it cannot tell apart (PlanIT Fig. 3): left-right mirrors, rotational-k turns, radial
    turns by 2 pi / :data:`RADIAL_FRAMES`. The first is ``frame`` itself."""
    if symmetry == "left-right":
        return [frame, frame.turned(0.0, True)]
    if symmetry == "front-back":
        return [frame, frame.turned(np.pi, True)]
    turns = {"rotational-2": 2, "rotational-4": 4, "radial": RADIAL_FRAMES}.get(symmetry, 1)
    return [frame.turned(2 * np.pi * k / turns) for k in range(turns)]


def side_in(frame: Frame, base: Frame, side: str) -> str:
    """The name in ``frame`` of the side called ``side`` in ``base`` (same origin): where that side's outward
    normal points in the other frame."""
    normal = {"front": (0.0, 1.0), "back": (0.0, -1.0), "left": (-1.0, 0.0), "right": (1.0, 0.0)}[side]
    v = to_local(Frame((0.0, 0.0), frame.yaw, frame.mirror), to_world(Frame((0.0, 0.0), base.yaw, base.mirror),
                                                                       np.array(normal)))
    k = int(np.argmax([v[1], -v[1], -v[0], v[0]]))
    return SIDES[k]
