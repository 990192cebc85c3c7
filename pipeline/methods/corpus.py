"""Reading what every method may read of one room type (:class:`~pipeline.methods.interface.Corpus`) and another
method's generated rooms (:class:`~pipeline.methods.interface.Generated`)."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from .. import tables
from ..graphs.files import read_split
from ..room import load_rooms
from .interface import Corpus, Generated


def load_corpus(room_type: str, files: Mapping[str, Any]) -> Corpus:
    """One room type's :class:`~pipeline.methods.interface.Corpus` from its ``files`` (a stage's inputs): the
    ``rooms``, ``architecture``, ``objects`` and ``models`` shards, its ``split`` table, the ``symmetry`` and
    ``category_sizes`` tables (None: absent)."""
    rooms, architecture, objects, models = files["rooms"], files["architecture"], files["objects"], files["models"]
    split, symmetry, category_sizes = files["split"], files["symmetry"], files["category_sizes"]
    room_df, arch, objs, inputs = load_rooms(rooms, architecture, objects)
    room_df = room_df[room_df["room_type"].astype(str) == room_type]
    ids = set(room_df["room_id"])
    objs = objs[objs["room_id"].isin(ids)]
    meshes, box_models = tables.read_meshes_of(models, objs["model_id"].dropna())
    return Corpus(room_type, room_df, arch[arch["room_id"].isin(ids)], objs,
                  {k: v for k, v in inputs.items() if k in ids}, read_split(split), list(models), symmetry,
                  category_sizes, meshes, box_models)


def load_generated(rooms: Path, architecture: Path, objects: Path, scenes: Path) -> Generated:
    read = lambda path, schema: tables.read(path, schema).to_pandas()
    return Generated(read(rooms, "rooms"), read(architecture, "architecture"), read(objects, "generated_objects"),
                     read(scenes, "scenes"))
