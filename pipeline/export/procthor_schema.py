"""A JSON Schema (2020-12) of a ProcTHOR-style house, written from the format's documented fields: the ``procthor``
package's ``HouseDict`` types (``procthor/utils/types.py``: rooms, walls, doors, windows, objects, procedural
parameters) and AI2-THOR's house schema 1.0.0 for what that package predates (doors' and windows' ``holePolygon`` and
``assetPosition`` on ``wall0``). Units: metres and degrees; Unity's axes (left-handed, y up)."""
from __future__ import annotations

_V3 = {"type": "object", "required": ["x", "y", "z"], "properties": {k: {"type": "number"} for k in "xyz"}}
_ID = {"type": "string", "minLength": 1}
_MATERIAL = {"type": "object", "required": ["name"], "properties": {"name": _ID}}


def _hole(extra: dict) -> dict:
    """A door or window: an asset in a hole of ``wall0`` (its room ``room0``), seen from ``wall1`` (``room1``).
    ``holePolygon``: two corners (start along the wall, bottom) and (end, top) in the wall's frame."""
    return {"type": "object",
            "required": ["id", "assetId", "room0", "room1", "wall0", "wall1", "holePolygon", "assetPosition"],
            "properties": {"id": _ID, "assetId": _ID, "room0": _ID, "room1": _ID, "wall0": _ID, "wall1": _ID,
                           "holePolygon": {"type": "array", "items": {"$ref": "#/$defs/vector3"}, "minItems": 2,
                                           "maxItems": 2},
                           "assetPosition": {"$ref": "#/$defs/vector3"}, **extra}}


HOUSE_SCHEMA = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "ProcTHOR-style house",
    "type": "object",
    "required": ["rooms", "walls", "doors", "windows", "objects", "proceduralParameters", "metadata"],
    "$defs": {
        "vector3": _V3,
        "object": {"type": "object", "required": ["id", "assetId", "position", "rotation", "kinematic"],
                   "properties": {"id": _ID, "assetId": _ID, "position": {"$ref": "#/$defs/vector3"},
                                  "rotation": {"$ref": "#/$defs/vector3"}, "kinematic": {"type": "boolean"},
                                  "children": {"type": "array", "items": {"$ref": "#/$defs/object"}}}},
    },
    "properties": {
        "rooms": {"type": "array", "minItems": 1, "items": {
            "type": "object", "required": ["id", "roomType", "floorPolygon", "children", "ceilings"],
            "properties": {"id": _ID, "roomType": _ID, "floorMaterial": _MATERIAL, "children": {"type": "array"},
                           "ceilings": {"type": "array"},
                           "floorPolygon": {"type": "array", "items": {"$ref": "#/$defs/vector3"}, "minItems": 3}}}},
        "walls": {"type": "array", "minItems": 3, "items": {
            "type": "object", "required": ["id", "roomId", "polygon"],
            "properties": {"id": _ID, "roomId": _ID, "material": _MATERIAL, "empty": {"type": "boolean"},
                           "polygon": {"type": "array", "items": {"$ref": "#/$defs/vector3"}, "minItems": 4,
                                       "maxItems": 4}}}},
        "doors": {"type": "array", "items": _hole({"openable": {"type": "boolean"},
                                                   "openness": {"type": "number", "minimum": 0, "maximum": 1}})},
        "windows": {"type": "array", "items": _hole({})},
        "objects": {"type": "array", "items": {"$ref": "#/$defs/object"}},
        "proceduralParameters": {
            "type": "object", "required": ["floorColliderThickness", "receptacleHeight", "lights", "reflections"],
            "properties": {"ceilingMaterial": _MATERIAL, "floorColliderThickness": {"type": "number"},
                           "receptacleHeight": {"type": "number"}, "lights": {"type": "array"},
                           "reflections": {"type": "array"}, "skyboxId": {"type": "string"}}},
        "metadata": {"type": "object", "required": ["schema"], "properties": {"schema": {"const": "1.0.0"}}},
    },
}
