"""Rooms as USD stages (``usd-core``'s ``pxr``): one stage per room, y up, metres.

Layout of a stage (``docs/formats.md``)::

    class "Prototypes"                   each model's mesh once, y-up model space (not drawn: a class)
        def Mesh "model_<k>"             planit:modelId, planit:category
    def Xform "Room"                     the default prim: planit:roomId, planit:roomType, planit:source
        def Scope "Architecture"
            def Mesh "floor" | "wall_<i>" | "door_<i>" | "window_<i>"   planit:kind, planit:elementId; world points
        def Scope "Objects"
            def Xform "<object id>"      translate + rotateY (relative to its support parent's prim, where nested);
                                         planit:category, planit:modelId, planit:nodeId
                def Mesh "geom"          scale, and a reference to its model's prototype
                def Xform "<object id>"  an object it supports, nested
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from pxr import Sdf, Tf, Usd, UsdGeom, Vt

from ..placement.layout import walls_of
from ..room import RoomInput
from .rooms import RoomSet, file_name, nesting
from .shapes import architecture, y_up

PROTOTYPES = "/Prototypes"


def write(rs: RoomSet, out: Path, options: dict) -> dict:
    """One stage per room of ``rs`` in ``out`` (``<room id>.usda`` or ``.usdc``: ``options['usd_extension']``)."""
    ext = options.get("usd_extension", "usdc")
    names = []
    for room in rs.rooms:
        name = f"{file_name(room.room_id)}.{ext}"
        stage = Usd.Stage.CreateNew(str(Path(out) / name))
        room_stage(stage, room, rs)
        stage.GetRootLayer().Save()
        names.append(name)
    return {"format": "usd", "rooms": len(names), "objects": sum(len(r.object_ids) for r in rs.rooms), "files": names}


def room_stage(stage: Usd.Stage, room: RoomInput, rs: RoomSet) -> None:
    """Fill an empty stage with one room: axes, prototypes, architecture and nested objects."""
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/Room").GetPrim()
    stage.SetDefaultPrim(root)
    _attrs(root, roomId=room.room_id, roomType=room.room_type, source=rs.sources.get(room.room_id, ""))
    stage.CreateClassPrim(PROTOTYPES)
    protos: dict[str, str] = {}
    for model in dict.fromkeys(room.model_ids):
        protos[model] = f"{PROTOTYPES}/model_{len(protos)}"
        v, f = rs.meshes[model]
        _mesh(stage, protos[model], y_up(v), f)
        _attrs(stage.GetPrimAtPath(protos[model]), modelId=model,
               category=room.categories[room.model_ids.index(model)])
    UsdGeom.Scope.Define(stage, "/Room/Architecture")
    for element, kind, (v, f) in architecture(room, walls_of(room)):
        prim = _mesh(stage, f"/Room/Architecture/{Tf.MakeValidIdentifier(element)}", y_up(v), f)
        _attrs(prim, kind=kind, elementId=element)
    UsdGeom.Scope.Define(stage, "/Room/Objects")
    _objects(stage, room, rs.parents[room.room_id], protos)


def _objects(stage: Usd.Stage, room: RoomInput, parents: list[str | None], protos: dict[str, str]) -> None:
    """Each object an Xform (nested under its support parent's), its mesh a scaled reference to its prototype."""
    path: dict[int, str] = {}
    for k, p in nesting(room.object_ids, parents):
        path[k] = f"{path[p] if p >= 0 else '/Room/Objects'}/{Tf.MakeValidIdentifier(room.object_ids[k])}"
        xf = UsdGeom.Xform.Define(stage, path[k])
        t, yaw = relative_pose(room.poses[k], room.poses[p] if p >= 0 else None)
        xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(tuple(float(c) for c in y_up(t)[0]))
        xf.AddRotateYOp(UsdGeom.XformOp.PrecisionDouble).Set(math.degrees(yaw))
        _attrs(xf.GetPrim(), category=room.categories[k], modelId=room.model_ids[k], nodeId=room.object_ids[k])
        geom = stage.DefinePrim(f"{path[k]}/geom", "Mesh")
        geom.GetReferences().AddInternalReference(protos[room.model_ids[k]])
        sx, sy, sz = (float(s) for s in room.poses[k, 4:7])
        UsdGeom.Xformable(geom).AddScaleOp(UsdGeom.XformOp.PrecisionDouble).Set((sx, sz, sy))


def relative_pose(pose: np.ndarray, parent: np.ndarray | None) -> tuple[np.ndarray, float]:
    """An object's origin ``(3,)`` and yaw (z-up) in its parent's frame (``pose``: px, py, pz, yaw, sx, sy, sz)."""
    if parent is None:
        return pose[:3], float(pose[3])
    d, c, s = pose[:3] - parent[:3], math.cos(parent[3]), math.sin(parent[3])
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]]), float(pose[3] - parent[3])


def _mesh(stage: Usd.Stage, path: str, points: np.ndarray, faces: np.ndarray) -> Usd.Prim:
    """A Mesh prim of ``(n, 3)`` points and ``(m, 3)`` triangles, with its extent."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    pts = np.ascontiguousarray(points, np.float32)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pts))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(faces), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.ascontiguousarray(faces, np.int32).ravel()))
    mesh.CreateExtentAttr(Vt.Vec3fArray.FromNumpy(np.stack([pts.min(0), pts.max(0)])))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    return mesh.GetPrim()


def _attrs(prim: Usd.Prim, **values: str) -> None:
    """Custom string attributes ``planit:<name>``."""
    for name, value in values.items():
        prim.CreateAttribute(f"planit:{name}", Sdf.ValueTypeNames.String, custom=True).Set(str(value))

