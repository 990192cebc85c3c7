"""The room model: one room as arrays, its walls, the canonical column order, and reading rooms from the
canonical tables. Every other package (extraction, placement, evaluation, the learners) takes rooms from here."""
from .load import load_rooms, room_inputs, room_slices
from .model import BOX_COLUMNS, POSE_COLUMNS, RoomInput, Walls, door_segments, door_zones_of, merge_walls, wall_footprints

__all__ = ["BOX_COLUMNS", "POSE_COLUMNS", "RoomInput", "Walls", "door_segments", "door_zones_of", "merge_walls",
           "wall_footprints", "load_rooms", "room_inputs", "room_slices"]
