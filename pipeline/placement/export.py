"""A generated room as files a person opens: a GLB and a top-down PNG with the planned graph drawn over it.

The GLB follows glTF's axes, +y up: the project's z-up geometry hangs under one root node ``room`` whose transform
maps project (x, y, z) to glTF (x, z, -y) (-90 degrees about x), so a viewer shows the floor at y = 0 and the walls
rising along +y. Under the root: ``floor``, one node per wall, door or window (its element id) and one per object (its
id). Node extras (the glTF ``nodes[i].extras``): ``{"kind": "floor"}``, ``{"kind": "wall"}``, ``{"kind": "door"}`` or
``{"kind": "window"}``, and for an object ``{"category", "model_id", "object_id"}``."""
from __future__ import annotations

import numpy as np

from ..geometry import meshes
from ..geometry.boxes import footprint_corners
from ..geometry.frames import front_of
from ..geometry.polygon import nearest_segment
from ..room import RoomInput, Walls, wall_footprints
from .plan import PlanEdge

EDGE_COLOURS = {"support": "black", "adjacent": "tab:red", "proximal": "tab:orange", "distant": "tab:blue"}
ROOT = "room"
Z_UP_TO_Y_UP = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])  # (x, y, z) -> (x, z, -y)
OPENING_MARGIN = 0.05  # an opening's box is this much thicker than its wall, so it shows through both faces
DEFAULT_THICKNESS = 0.1


def floor_mesh(outline: np.ndarray) -> meshes.Mesh:
    """A 2 cm slab under the ``(k, 2)`` outline, its top at z = 0."""
    import shapely

    tris = shapely.constrained_delaunay_triangles(shapely.Polygon(outline))  # GEOS: no extra triangulation engine
    corners = np.array([np.asarray(t.exterior.coords)[:3] for t in tris.geoms])  # (t, 3, 2)
    d1, d2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    clockwise = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] < 0
    corners[clockwise] = corners[clockwise, ::-1]  # prisms take counter-clockwise outlines
    return meshes.prisms(corners, -0.02, 0.0)


def opening_mesh(opening: dict, walls: Walls) -> meshes.Mesh:
    """A door or window as a box over its segment, from z0 to z1, through the nearest wall and 5 cm thicker.

    Its depth is the opening's ``thickness`` or else the nearest wall's; it is centred on the wall's middle, behind
    the inner face (``(w, 2)`` normals point into the room)."""
    p0, p1 = np.array([opening["x0"], opening["y0"]], float), np.array([opening["x1"], opening["y1"]], float)
    mid, length = (p0 + p1) / 2, float(np.linalg.norm(p1 - p0))
    d = (p1 - p0) / max(length, 1e-9)
    normal, thick = np.array([-d[1], d[0]]), DEFAULT_THICKNESS
    if len(walls.ids):
        k = int(nearest_segment(mid, walls.segments)[1])
        normal = normal if normal @ walls.normal[k] >= 0 else -normal
        thick = float(walls.thickness[k])
    if opening.get("thickness") is not None and np.isfinite(opening["thickness"]):
        thick = float(opening["thickness"])
    z0, z1 = float(opening["z0"]), float(opening["z1"])
    v, f = meshes.box((length, thick + OPENING_MARGIN, z1 - z0), (0.0, 0.0, (z0 + z1) / 2))
    centre = mid - normal * thick / 2
    return meshes.transform(v, (centre[0], centre[1], 0.0), float(np.arctan2(d[1], d[0]))), f


def _add(scene, name: str, mesh: meshes.Mesh, extras: dict) -> None:
    """One node ``name`` under the root, its mesh ``(vertices (n, 3), faces (m, 3))`` z-up, ``extras`` on the node."""
    import trimesh

    geom = trimesh.Trimesh(mesh[0], mesh[1], process=False)
    geom.metadata.update(extras)
    scene.add_geometry(geom, node_name=name, geom_name=name, parent_node_name=ROOT, metadata=dict(extras))


def room_scene(room: RoomInput, walls: Walls, mesh_of):
    """A trimesh Scene of the room, y-up: root ``room`` over ``floor``, walls, doors, windows and objects."""
    import trimesh

    scene = trimesh.Scene()
    scene.graph.update(frame_from=scene.graph.base_frame, frame_to=ROOT, matrix=Z_UP_TO_Y_UP)
    _add(scene, "floor", floor_mesh(room.outline), {"kind": "floor"})
    for wid, corners in zip(walls.ids, wall_footprints(walls)):
        _add(scene, wid, meshes.prisms(corners[None], 0.0, walls.height), {"kind": "wall"})
    for o in room.openings:
        _add(scene, str(o["element_id"]), opening_mesh(o, walls), {"kind": str(o["kind"])})
    for oid, cat, model, pose in zip(room.object_ids, room.categories, room.model_ids, room.poses):
        mesh = mesh_of(model)
        if mesh is None or not len(mesh[1]):
            continue
        v = meshes.transform(mesh[0], pose[:3], pose[3], pose[4:])
        _add(scene, oid, (v, mesh[1]), {"category": cat, "model_id": model, "object_id": oid})
    return scene


def glb(room: RoomInput, walls: Walls, mesh_of) -> bytes:
    """The room as a binary glTF, y-up (``room_scene``)."""
    return room_scene(room, walls, mesh_of).export(file_type="glb")


def plan_figure(room: RoomInput, walls: Walls, edges: list[PlanEdge], title: str):
    """Top-down figure: floor, walls, openings, footprints with ids, planned edges coloured by type."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    fig, ax = plt.subplots(figsize=(5, 5))
    ax.add_patch(Polygon(room.outline, closed=True, facecolor="0.93", edgecolor="none"))
    for corners in wall_footprints(walls):
        ax.add_patch(Polygon(corners, closed=True, facecolor="0.35", edgecolor="none"))
    for o in room.openings:
        ax.plot([o["x0"], o["x1"]], [o["y0"], o["y1"]], color="tab:green" if o["kind"] == "door" else "tab:cyan", lw=4)
    cmap = plt.get_cmap("tab20")
    cats = sorted(set(room.categories))
    centre = {w: (a + b) / 2 for w, a, b in zip(walls.ids, walls.a, walls.b)}
    b = room.boxes
    for k, (oid, cat) in enumerate(zip(room.object_ids, room.categories)):
        fp = footprint_corners(*b[k, [0, 1, 3, 4, 6]])[0]
        ax.add_patch(Polygon(fp, closed=True, facecolor=cmap(cats.index(cat) % 20), alpha=0.55, edgecolor="k", lw=0.6))
        front = b[k, :2] + front_of(b[k, 6]) * b[k, 4]
        ax.plot(*zip(b[k, :2], front), color="k", lw=0.6)
        ax.text(*b[k, :2], f"{oid}\n{cat}", fontsize=5, ha="center", va="center")
        centre[oid] = b[k, :2]
    for e in edges:
        if e.source in centre and e.target in centre:
            colour = EDGE_COLOURS["support" if e.edge_type == "support" else e.distance]
            ax.annotate("", centre[e.target], centre[e.source], arrowprops={"arrowstyle": "->", "color": colour, "lw": 0.8,
                        "ls": ":" if e.edge_type == "support" else "-"})
    lo, hi = room.outline.min(0) - 0.3, room.outline.max(0) + 0.3
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), aspect="equal", title=title)
    ax.tick_params(labelsize=6)
    for name, colour in EDGE_COLOURS.items():
        ax.plot([], [], color=colour, label=name)
    ax.legend(fontsize=6, loc="upper right")
    fig.tight_layout()
    return fig
