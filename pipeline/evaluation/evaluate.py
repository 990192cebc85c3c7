"""Score every method's rooms of one room type and the held-out real rooms by the same functions: per scene the
physical metrics, walkability and nearest-training-room similarity; per set the category and object-count distances
beside their sampling floors, the collision, out-of-bounds and walkability rates, graph consistency and the
real-vs-synthetic classifier accuracy."""
from __future__ import annotations

import pandas as pd

from .. import tables
from ..geometry.raycast import intersector_class
from ..placement.checks import Checker
from . import render
from .scores import finite, floors, goals, label_maps, rule_satisfaction, scene_rows, set_summary, train_similarity
from .sets import REAL, RoomSet

SETTINGS = ("render", "walk", "collision", "out_of_bounds", "sca", "kl_eps")


def evaluate_room_type(config: dict, room_type: str, gen: list[RoomSet], train: RoomSet, real: RoomSet, meshes: dict,
                       box_models: set, symmetry: dict, threads: int = 1) -> tuple[dict, pd.DataFrame]:
    """``metrics.json``'s content and the ``eval_scenes`` rows of every set (``gen``: the methods' sets, the first
    one's goals reported)."""
    ev = config["evaluate"]
    index = {c: k for k, c in enumerate(sorted({c for s in (train, real, *gen) for r in s.rooms for c in r.categories}))}
    train_maps = label_maps(train, index, ev["render"])
    train_ids = [r.room_id for r in train.rooms]
    by_name = {rs.name: rs for rs in (*gen, real)}
    rows = {name: pd.DataFrame(scene_rows(rs, meshes, box_models, train_maps, train_ids, index, config),
                               columns=tables.SCHEMAS["eval_scenes"].names) for name, rs in by_name.items()}
    sets = {name: set_summary(frame, by_name[name], real, ev["kl_eps"]) for name, frame in rows.items()}
    for name, score in classifier_scores(config, by_name, train_maps, real, index, threads).items():
        sets[name]["sca"] = score
    if config["source"] == "procedural":  # the generator's own rules: an oracle only for its rooms
        checker = Checker(meshes, box_models, symmetry, {**config["extract"], "floor_contact": config["floor_contact"]},
                          intersector_class(config["extract"]["backend"]), {})
        for name, rs in by_name.items():
            sets[name]["rules"] = rule_satisfaction(rs, checker)
    fl = floors(train, real, len(gen[0].rooms), ev, config["seed"])
    metrics = finite({"room_type": room_type, "sets": sets, "floors": fl,
                      "train_nn_similarity": train_similarity(train_maps, ev["similarity_sample"], config["seed"]),
                      "goals": goals(sets, fl, gen[0].name, REAL), "real_train_rooms": len(train.rooms),
                      "settings": {k: ev[k] for k in SETTINGS}, "categories": sorted(index)})
    return metrics, pd.concat(list(rows.values()), ignore_index=True)


def classifier_scores(config: dict, by_name: dict, train_maps, real: RoomSet, index: dict, threads: int) -> dict:
    """The real-vs-synthetic classifier's accuracy for every generated set (trained from scratch per set)."""
    from .sca import sca_scores

    ev = config["evaluate"]
    colours = render.palette(sorted(index))
    real_maps = (render.to_rgb(train_maps, colours), render.to_rgb(label_maps(real, index, ev["render"]), colours))
    return {name: sca_scores(real_maps, render.to_rgb(label_maps(rs, index, ev["render"]), colours), ev["sca"],
                             threads, config["seed"])
            for name, rs in by_name.items() if name != REAL}
