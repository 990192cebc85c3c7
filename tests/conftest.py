"""Shared test helpers: hand-built rooms as canonical rows, and a real extraction call."""
from __future__ import annotations

import math
import os
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from hypothesis import settings

from pipeline import config as config_mod
from pipeline.extraction import extract_room
from pipeline.geometry import meshes
from pipeline.geometry.polygon import polygon_segments
from pipeline.geometry.raycast import intersector_class
from pipeline.room import room_inputs

ROOT = Path(__file__).resolve().parents[1]
# Real sample data (never copied into the repository): PLANIT_SHARED_DATA, by default ../shared/data beside the clone.
SHARED_DATA = Path(os.environ.get("PLANIT_SHARED_DATA", ROOT.parent / "shared" / "data"))

# Property tests: the default profile is derandomized (every run tries the same 200 cases, so CI is
# reproducible); HYPOTHESIS_PROFILE=deep searches 5,000 fresh random cases per property.
settings.register_profile("default", max_examples=200, deadline=None, derandomize=True)
settings.register_profile("deep", max_examples=5000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


class Room:
    """A room built by hand: outline, walls, openings, box-mesh or custom-mesh objects."""

    def __init__(self, outline, height=2.7, room_id="r0", room_type="bedroom"):
        self.outline = np.asarray(outline, float)
        self.height = height
        self.room_id = room_id
        self.room_type = room_type
        self.objects: list[dict] = []
        self.models: dict[str, tuple] = {}
        self.openings: list[dict] = []

    def add(self, object_id, category, size, centre_xy, yaw_deg=0.0, z=0.0, mesh=None, parent=None):
        """Object of full ``size`` (w, d, h) standing at height ``z``; its mesh is a box unless given."""
        w, d, h = size
        model_id = f"m_{object_id}"
        self.models[model_id] = mesh if mesh is not None else meshes.box((w, d, h), (0, 0, h / 2))
        yaw = math.radians(yaw_deg)
        self.objects.append({"room_id": self.room_id, "object_id": object_id, "category": category, "model_id": model_id,
                             "cx": centre_xy[0], "cy": centre_xy[1], "cz": z + h / 2, "hx": w / 2, "hy": d / 2, "hz": h / 2,
                             "yaw": yaw, "px": centre_xy[0], "py": centre_xy[1], "pz": z, "sx": 1.0, "sy": 1.0, "sz": 1.0,
                             "source_parent_id": parent})
        return self

    def door(self, element_id, p0, p1, wall_id):
        self.openings.append({"room_id": self.room_id, "element_id": element_id, "kind": "door", "x0": p0[0], "y0": p0[1],
                              "x1": p1[0], "y1": p1[1], "z0": 0.0, "z1": 2.0, "thickness": None, "wall_id": wall_id})
        return self

    def walls(self) -> pd.DataFrame:
        segs = polygon_segments(self.outline)
        return pd.DataFrame([{"room_id": self.room_id, "element_id": f"wall_{i}", "kind": "wall", "x0": s[0][0], "y0": s[0][1],
                              "x1": s[1][0], "y1": s[1][1], "z0": 0.0, "z1": self.height, "thickness": 0.15, "wall_id": None}
                             for i, s in enumerate(segs)])

    def row(self):
        xs, ys = self.outline[:, 0], self.outline[:, 1]
        return SimpleNamespace(room_id=self.room_id, room_type=self.room_type, height=self.height, floor_x=xs.tolist(),
                               floor_y=ys.tolist(), extent_x=float(np.ptp(xs)), extent_y=float(np.ptp(ys)))

    def objects_df(self) -> pd.DataFrame:
        cols = ["room_id", "object_id", "category", "model_id", "cx", "cy", "cz", "hx", "hy", "hz", "yaw", "px", "py", "pz",
                "sx", "sy", "sz", "source_parent_id"]
        return pd.DataFrame(self.objects, columns=cols)

    def openings_df(self) -> pd.DataFrame:
        cols = ["room_id", "element_id", "kind", "x0", "y0", "x1", "y1", "z0", "z1", "thickness", "wall_id"]
        return pd.DataFrame(self.openings, columns=cols)

    def room_input(self, walls=None):
        rooms = pd.DataFrame([vars(self.row())])
        arch = pd.concat([walls if walls is not None else self.walls(), self.openings_df()], ignore_index=True)
        return next(room_inputs(rooms, arch, self.objects_df()))

    def extract(self, backend="embree", symmetry=None, cfg=None, walls=None, box_models=None):
        """The room's raw graph; ``box_models`` as extract_room's (None: every model is box-only)."""
        defaults = default_config()
        cfg = {"floor_contact": defaults["floor_contact"], **(cfg or defaults["extract"])}
        symmetry = symmetry or {}
        return extract_room(self.room_input(walls), self.models.get, lambda c, m: (symmetry.get(c, "none"), "table"),
                            cfg, intersector_class(backend), box_models)


def default_config() -> dict:
    return config_mod.validate({})


def edge(graph, src, dst, edge_type="spatial"):
    """The one edge src -> dst of a type, or None."""
    e = [x for x in graph.edges if x["source"] == src and x["target"] == dst and x["edge_type"] == edge_type]
    assert len(e) <= 1
    return e[0] if e else None


def shared_data(sub: str) -> Path:
    path = SHARED_DATA / sub
    if not path.exists():
        pytest.skip(f"real sample data not found at {path} (set PLANIT_SHARED_DATA; a fresh clone has no ../shared)")
    return path


def table_mesh(w, d, h, top=0.03, leg=0.05):
    """A four-legged table (model frame: bottom centre at the origin)."""
    legs = [meshes.box((leg, leg, h - top), (sx * (w / 2 - leg), sy * (d / 2 - leg), (h - top) / 2))
            for sx in (-1, 1) for sy in (-1, 1)]
    return meshes.combine([meshes.box((w, d, top), (0, 0, h - top / 2)), *legs])


def l_sofa_mesh():
    """An L-shaped sofa: a 2.4 x 0.9 m seat along y = -0.75 and a 0.9 x 1.6 m chaise along x = +0.75 (local)."""
    return meshes.combine([meshes.box((2.4, 0.9, 0.8), (0.0, -0.75, 0.4)), meshes.box((0.9, 1.6, 0.8), (0.75, 0.4, 0.4))])
