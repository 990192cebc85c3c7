"""Score every method's rooms of one room type and the held-out real rooms by the same functions: per scene the
physical metrics, walkability, nearest-training-room similarity and the functional checks learned from the training
rooms; per set the category and object-count distances beside their sampling floors, the collision, out-of-bounds
and walkability rates, graph consistency and the functional checks' shares, each with a bootstrap 95% interval and
its difference from the first method and from the real rooms; the real-vs-synthetic classifier's accuracy after its
power check."""
from __future__ import annotations

from collections import Counter
from typing import Any

import numpy as np
import pandas as pd

from .. import tables
from ..geometry.function import off_axis
from ..geometry.raycast import intersector_class
from ..placement.checks import Checker
from ..room import RoomInput
from . import distributions, functional, intervals, power, render
from .scores import finite, floors, goals, label_maps, rule_satisfaction, scene_rows, set_counts, train_similarity
from .sets import REAL, RoomSet

SETTINGS = ("render", "walk", "cooccurrence_min_share", "collision", "out_of_bounds", "sca", "kl_eps", "functional", "power", "bootstrap",
            "bootstrap_min_rooms", "off_axis_angle", "off_axis_min_objects")
EXTRA = ["consistency", "violation", "nn_similarity", "contents_excess", "contents_missing", "functional_all"]


def evaluate_room_type(config: dict[str, Any], room_type: str, gen: list[RoomSet], train: RoomSet, real: RoomSet,
                       models: tuple[dict[str, Any], set[str], dict[str, str]],
                       threads: int = 1) -> tuple[dict[str, Any], pd.DataFrame]:
    """``metrics.json``'s content and the ``eval_scenes`` rows of every set (``gen``: the methods' sets, the first
    the reference of the differences and goals; ``models``: meshes, box-only model ids, model -> symmetry type)."""
    meshes, box_models, symmetry, ev = *models, config["evaluate"]
    index = {c: k for k, c in enumerate(sorted({c for s in (train, real, *gen) for r in s.rooms for c in r.categories}))}
    train_maps = label_maps(train, index, ev["render"])
    learned = functional.learn_checks(train.rooms, ev["functional"], symmetry)
    by_name = {rs.name: rs for rs in (*gen, real)}
    rows = {name: room_rows(rs, learned, index, models, train_maps,
                            [r.room_id for r in train.rooms], config) for name, rs in by_name.items()}
    checks = [functional.check_name(c) for c in learned["checks"]]
    stat = lambda frame, ref: intervals.figures(frame, ref, ev["kl_eps"], EXTRA + checks)
    reps = intervals.bootstrap(rows, REAL, stat, ev["bootstrap"], config["seed"])
    spans = intervals.intervals(reps)
    sets = {name: {**set_counts(rows[name], rs), **stat(rows[name], rows[REAL]), "intervals": spans[name]}
            for name, rs in by_name.items()}
    for name, rs in by_name.items():
        sets[name]["cooccurrence_similarity"] = distributions.cooccurrence_similarity(
            [r.categories for r in train.rooms], [r.categories for r in rs.rooms], ev["cooccurrence_min_share"])
    sca, check = classifier_scores(config, by_name, train, real, index, threads)
    for name, score in sca.items():
        sets[name]["sca"] = score
    if config["source"] == "procedural":  # the generator's own rules: an oracle only for its rooms
        checker = Checker(meshes, box_models, symmetry, {**config["extract"], "floor_contact": config["floor_contact"]},
                          intersector_class(config["extract"]["backend"]), {})
        for name, rs in by_name.items():
            sets[name]["rules"] = rule_satisfaction(rs, checker)
    axis = {name: off_axis_shares(rs.rooms, symmetry, ev["off_axis_angle"]) for name, rs in {**by_name, "real_train": train}.items()}
    for name in by_name:
        sets[name]["off_axis_share"] = axis[name]["all"]
        sets[name]["off_axis_gap"] = off_axis_gap(axis[name], axis["real_train"], ev["off_axis_min_objects"])
    fl = floors(train, real, len(gen[0].rooms), ev, config["seed"])
    metrics = {"room_type": room_type, "sets": sets, "floors": fl, "functional": learned, "checks": checks,
               "differences": {f"vs_{ref}": intervals.differences(reps, ref, {n: len(f) for n, f in rows.items()},
                                                                   ev["bootstrap_min_rooms"], REAL)
                               for ref in (gen[0].name, REAL)},
               "power": check,
               "train_nn_similarity": train_similarity(train_maps, ev["similarity_sample"], config["seed"]),
               "real_train_rooms": len(train.rooms), "settings": {k: ev[k] for k in SETTINGS}, "off_axis": axis,
               "categories": sorted(index)}
    metrics["goals"] = goals(metrics, gen[0].name, REAL)
    scenes = pd.concat([f[tables.SCHEMAS["eval_scenes"].names] for f in rows.values()], ignore_index=True)
    return finite(metrics), scenes


def room_rows(rs: RoomSet, learned: dict[str, Any], index: dict[str, int],
              models: tuple[dict[str, Any], set[str], dict[str, str]], train_maps: np.ndarray, train_ids: list[str],
              config: dict[str, Any]) -> pd.DataFrame:
    """One row per room: the ``eval_scenes`` columns, each functional check's outcome and the category counts
    (``models``: meshes, box-only models and the model -> symmetry table)."""
    meshes, box_models, symmetry = models
    scored = pd.DataFrame(scene_rows(rs, meshes, box_models, train_maps, train_ids, index, config),
                          columns=[c for c in tables.SCHEMAS["eval_scenes"].names
                                   if c not in (*functional.ROOM_COLUMNS, "failed_checks")])
    fn = pd.DataFrame([functional.score_room(r, learned, config["evaluate"]["functional"], symmetry) for r in rs.rooms],
                      index=scored.index, columns=[*map(functional.check_name, learned["checks"]),
                                                   *functional.ROOM_COLUMNS], dtype=float)
    counts = pd.DataFrame([Counter(r.categories) for r in rs.rooms], index=scored.index,
                          columns=sorted(index)).fillna(0).add_prefix(intervals.CATEGORY)
    failed = pd.Series([failed_checks(o) for o in fn.to_dict("records")], index=scored.index, name="failed_checks")
    return pd.concat([scored, fn, counts, failed], axis=1)


def failed_checks(outcomes: dict[str, float]) -> list[str]:
    """The checks one room fails (outcome 0.0, ``fn:`` prefix dropped), then the contents flags it raises."""
    flags = [k for k in functional.ROOM_COLUMNS if k != "functional_all" and outcomes[k] == 1.0]
    return [k[3:] for k, v in outcomes.items() if k.startswith("fn:") and v == 0.0] + flags


def off_axis_shares(rooms: list[RoomInput], symmetry: dict[str, str], angle_deg: float) -> dict[str, Any]:
    """Share of objects turned more than ``angle_deg`` off their nearest wall's axes: over every object of the rooms
    (``all``) and per category (radially symmetric objects left out), with the objects counted (``counts``)."""
    off, cats = [], []
    for r in rooms:
        off.append(off_axis(r.boxes, r.outline, np.radians(angle_deg), functional.kinds(r, symmetry)))
        cats += list(r.categories)
    flags = pd.Series(np.concatenate(off) if off else np.zeros(0), index=cats, dtype=float).dropna()
    by = flags.groupby(level=0)
    return {"all": float(flags.mean()) if len(flags) else None,
            "categories": {c: round(float(v), 4) for c, v in by.mean().items()}, "counts": by.size().astype(int).to_dict()}


def off_axis_gap(shares: dict[str, Any], train: dict[str, Any], least: int) -> float | None:
    """The largest gap (share points) between a set's and the training rooms' off-axis shares over the categories
    both hold at least ``least`` (non-radial) objects of; None where there is none."""
    gaps = [abs(v - train["categories"][c]) for c, v in shares["categories"].items()
            if c in train["categories"] and shares["counts"][c] >= least and train["counts"][c] >= least]
    return round(float(max(gaps)), 4) if gaps else None


def classifier_scores(config: dict[str, Any], by_name: dict[str, RoomSet], train: RoomSet, real: RoomSet, index: dict[str, int],
                      threads: int) -> tuple[dict[str, Any], dict[str, Any]]:
    """The classifier's accuracy for every generated set, and for every power set and the real-vs-real control
    with the power check's verdict."""
    from .sca import sca_all

    ev = config["evaluate"]
    colours = render.palette(sorted(index))
    rgb = lambda rooms: render.classifier_images(rooms, index, colours, ev["render"])
    train_images, real_test = rgb(train.rooms), rgb(real.rooms)
    methods = {name: (rgb(rs.rooms), None, None) for name, rs in by_name.items() if name != REAL}
    own = np.arange(len(real.rooms))  # a power set's copies are grouped by the held-out room they come from
    known = {name: (rgb(rooms), groups, own)
             for name, (rooms, groups) in power.power_sets(real.rooms, ev["power"], config["seed"]).items()}
    kept, back = power.control_split(len(train.rooms), max(len(rs.rooms) for rs in by_name.values()), config["seed"])
    every = sca_all((train_images, real_test), {**methods, **known},
                    (train_images[kept], train_images[back], power.CONTROL), ev["sca"], threads, config["seed"])
    scores = {n: every[n] for n in methods}
    checks = {n: every[n] for n in (*known, power.CONTROL)}
    return scores, {"scores": checks, **power.verdict(checks, ev["power"])}
