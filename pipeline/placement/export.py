"""A generated room as files a person opens: a GLB (one node per object, named by its id, with its category in the
node's extras; walls and floor included) and a top-down PNG with the planned graph drawn over it."""
from __future__ import annotations

import numpy as np

from ..room import RoomInput, Walls, wall_footprints
from ..geometry import meshes
from ..geometry.boxes import footprint_corners
from .plan import PlanEdge

EDGE_COLOURS = {"support": "black", "adjacent": "tab:red", "proximal": "tab:orange", "distant": "tab:blue"}


def room_scene(room: RoomInput, walls: Walls, mesh_of):
    """A trimesh Scene of the room: ``floor``, one node per wall (its id) and per object (its id)."""
    import shapely
    import trimesh

    scene = trimesh.Scene()
    tris = shapely.constrained_delaunay_triangles(shapely.Polygon(room.outline))  # GEOS: no extra triangulation engine
    corners = np.array([np.asarray(t.exterior.coords)[:3] for t in tris.geoms])
    d1, d2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    clockwise = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] < 0
    corners[clockwise] = corners[clockwise, ::-1]  # prisms take counter-clockwise outlines
    v, f = meshes.prisms(corners, -0.02, 0.0)
    scene.add_geometry(trimesh.Trimesh(v, f, process=False), node_name="floor", geom_name="floor", metadata={"kind": "floor"})
    for wid, corners in zip(walls.ids, wall_footprints(walls)):
        v, f = meshes.prisms(corners[None], 0.0, walls.height)
        scene.add_geometry(trimesh.Trimesh(v, f, process=False), node_name=wid, geom_name=wid, metadata={"kind": "wall"})
    for oid, cat, model, pose in zip(room.object_ids, room.categories, room.model_ids, room.poses):
        mesh = mesh_of(model)
        if mesh is None or not len(mesh[1]):
            continue
        v = meshes.transform(mesh[0], pose[:3], pose[3], pose[4:])
        geom = trimesh.Trimesh(v, mesh[1], process=False)
        geom.metadata.update({"category": cat, "model_id": model})
        scene.add_geometry(geom, node_name=oid, geom_name=oid, metadata={"category": cat, "model_id": model})
    return scene


def glb(room: RoomInput, walls: Walls, mesh_of) -> bytes:
    """The room as a binary glTF (``room_scene``)."""
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
        front = b[k, :2] + np.array([-np.sin(b[k, 6]), np.cos(b[k, 6])]) * b[k, 4]
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
