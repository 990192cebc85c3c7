"""The relative poses of a room's edges and their mean-shift clusters (Kalojanov et al. 2019, section 6: each edge
type's relative placements cluster; a tagger picks a cluster per edge and the shape is assembled from them).

An edge's *relative pose* is its target's box centre and yaw in its anchor's frame: an object anchor's box frame
(metres, +y its front), or a wall's frame (origin mid-wall on its inner face, +y into the room) with the along-wall
coordinate divided by the wall's half length (rooms' walls differ in length; a bed centred on its wall is at 0).
Clusters are found per *triple* (anchor class, target category, edge class) by mean-shift over
``(x / position, y / position, cos(yaw) / chord, sin(yaw) / chord)`` with bandwidth 1 (``strings.tagger.bandwidth``:
``position`` m, ``along`` for a wall's fraction, ``angle`` degrees as the chord ``2 sin(angle / 2)``). Mean-shift
is scikit-learn's. Pure NumPy; no torch.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...graphs.data import N_OBJECT_EDGES, Graph, Vocab
from ...placement.prior import anchor_frame, from_relative, relative_pose  # noqa: F401 (from_relative: assemble's)
from ...room import RoomInput, Walls

Triple = tuple[str, str, int]  # anchor class name, target category, edge class


@dataclass(frozen=True)
class EdgePose:
    """One edge of a room (graph node indices) with its triple and the target's pose in the anchor's frame:
    ``pose (3,)``: x (m, or a wall's along fraction in [-1, 1]), y (m), yaw (rad, wrapped)."""
    source: int
    target: int
    edge_class: int
    triple: Triple
    pose: np.ndarray


def edge_poses(graph: Graph, vocab: Vocab, room: RoomInput, walls: Walls) -> list[EdgePose]:
    """The relative pose of every support and spatial edge of ``graph`` whose anchor is an object or a wall of
    ``room`` and whose target is one of its objects."""
    names, ids, out = vocab.node_classes, graph.node_ids, []
    for s, t, c in graph.edges[:, :3].tolist():
        if c >= N_OBJECT_EDGES or ids[t] not in room.object_ids:
            continue
        frame = anchor_frame(ids[s], room, walls)
        if frame is None:
            continue
        box = room.boxes[room.object_ids.index(ids[t])]
        out.append(EdgePose(s, t, c, (names[graph.node_class[s]], names[graph.node_class[t]], c),
                            relative_pose(*frame, box)))
    return out


def _scaled(poses: np.ndarray, wall: bool, bandwidth: dict) -> np.ndarray:
    """``(n, 4)`` features of ``poses (n, 3)`` in bandwidth units."""
    chord = 2 * np.sin(np.radians(bandwidth["angle"]) / 2)
    x = poses[:, 0] / (bandwidth["along"] if wall else bandwidth["position"])
    return np.column_stack([x, poses[:, 1] / bandwidth["position"], np.cos(poses[:, 2]) / chord,
                            np.sin(poses[:, 2]) / chord])


@dataclass
class Clusters:
    """Per triple: cluster centres ``(k, 3)`` (x, y, circular mean yaw), spreads ``(k, 2)`` (std of x and y),
    member counts ``(k,)``, and the global index of its first cluster (``offset``): the tagger's classes are the
    clusters of every triple, in order."""
    centres: dict[Triple, np.ndarray]
    spread: dict[Triple, np.ndarray]
    counts: dict[Triple, np.ndarray]
    offset: dict[Triple, int]
    bandwidth: dict

    @property
    def size(self) -> int:
        return sum(len(c) for c in self.centres.values())

    def label(self, triple: Triple, pose: np.ndarray) -> int | None:
        """The global index of the cluster nearest ``pose (3,)`` (in bandwidth units), None for an unseen triple."""
        if triple not in self.centres:
            return None
        wall = triple[0] == "wall"
        d = _scaled(self.centres[triple], wall, self.bandwidth) - _scaled(pose[None], wall, self.bandwidth)
        return self.offset[triple] + int(np.argmin((d ** 2).sum(1)))

    def to_record(self) -> dict:
        return {"bandwidth": self.bandwidth, "triples": [
            {"triple": list(t), "centres": self.centres[t].tolist(), "spread": self.spread[t].tolist(),
             "counts": self.counts[t].tolist()} for t in self.centres]}

    @classmethod
    def from_record(cls, rec: dict) -> "Clusters":
        cen, spr, cnt, off, k = {}, {}, {}, {}, 0
        for r in rec["triples"]:
            t = (r["triple"][0], r["triple"][1], int(r["triple"][2]))
            cen[t], spr[t], cnt[t] = np.array(r["centres"]), np.array(r["spread"]), np.array(r["counts"], int)
            off[t], k = k, k + len(cen[t])
        return cls(cen, spr, cnt, off, rec["bandwidth"])


def _cluster(poses: np.ndarray, wall: bool, bandwidth: dict) -> np.ndarray:
    """``(n,)`` mean-shift cluster labels of ``poses (n, 3)``, numbered by decreasing size."""
    from sklearn.cluster import MeanShift

    if len(poses) < 2:
        return np.zeros(len(poses), int)
    labels = MeanShift(bandwidth=1.0, bin_seeding=len(poses) > 50).fit(_scaled(poses, wall, bandwidth)).labels_
    by_size = np.argsort(-np.bincount(labels), kind="stable")
    return np.argsort(by_size)[labels]


def fit_clusters(poses: list[EdgePose], bandwidth: dict) -> Clusters:
    """Mean-shift clusters of the relative poses of every triple (triples sorted, clusters by decreasing size)."""
    by: dict[Triple, list[np.ndarray]] = {}
    for p in poses:
        by.setdefault(p.triple, []).append(p.pose)
    cen, spr, cnt, off, k = {}, {}, {}, {}, 0
    for t in sorted(by):
        x = np.array(by[t])
        labels = _cluster(x, t[0] == "wall", bandwidth)
        groups = [x[labels == j] for j in range(labels.max() + 1)]
        cen[t] = np.array([[*g[:, :2].mean(0), np.arctan2(np.sin(g[:, 2]).mean(), np.cos(g[:, 2]).mean())]
                           for g in groups])
        spr[t] = np.array([g[:, :2].std(0) for g in groups])
        cnt[t], off[t] = np.array([len(g) for g in groups]), k
        k += len(groups)
    return Clusters(cen, spr, cnt, off, dict(bandwidth))
