"""Collision measure on thin parts (issue 27): milliseconds per mesh pair of geometry.collision.mesh_penetration with
the grid alone (``surface_spacing: null``: the measure before) and with the surface screen (the default), for the
evaluation's, the instantiation checks' and the filter's settings, on one core:

- every pair of the real 3D-FRONT rooms (../shared/data/3d-front-meshes, real 3D-FUTURE meshes) whose oriented
  boxes overlap deeper than evaluate.collision.max_penetration, both with a mesh: the pairs the evaluation
  measures on meshes; and which of them change verdict at that limit;
- box-panel bookshelves (0.8 x 0.35 x 1.8 m, 2 cm panels) whose panels interleave, a small shelf standing in one's
  compartment without contact, and two copies of the sample's real 3D-FUTURE shelf interleaved (depths before and
  after).

    .venv/bin/python bench/collision.py [--sample ../shared/data/3d-front-meshes] [--repeat 5]
"""
from __future__ import annotations

import platform
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline import config as config_mod, tables
from pipeline.corpus.ingest import OUTPUTS
from pipeline.geometry import boxes, collision, meshes
from pipeline.geometry.raycast import intersector_class
from pipeline.stage import Files
from pipeline.stages import ingest

from common import OUT, ROOT, arguments, report

SHELF = "0d7421d4-2656-435b-9eb1-8884b4b3dcb3"  # the sample's one real "Shelf" with a mesh (0.34 x 0.34 x 1.73 m)


def bookshelf(shelves=5, width=0.8, depth=0.35, height=1.8, panel=0.02) -> meshes.Mesh:
    """Two side panels, a bottom, a top and ``shelves`` shelves between them, boxes ``panel`` thick concatenated."""
    side = [meshes.box((panel, depth, height), (s * (width - panel) / 2, 0, height / 2)) for s in (-1, 1)]
    step = (height - panel) / (shelves + 1)
    flat = [meshes.box((width - 2 * panel, depth, panel), (0, 0, panel / 2 + k * step)) for k in range(shelves + 2)]
    return meshes.combine(side + flat)


def timed(a, b, intersector, pen: collision.Measure, repeat: int) -> tuple[float, float]:
    """``(depth m, median ms)`` of ``mesh_penetration`` over ``repeat`` runs."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        d = collision.mesh_penetration(a, b, intersector, pen)
        times.append(time.perf_counter() - t)
    return d, 1000 * statistics.median(times)


def real_pairs(sample: Path, workdir: Path, limit: float) -> list[tuple[str, tuple, tuple]]:
    """``(label, mesh a, mesh b)`` in world coordinates for the sample rooms' pairs whose boxes overlap deeper than
    ``limit``, both with a real mesh."""
    cfg = config_mod.validate({"source": "front3d", "shards": 1, "front3d": {
        "houses": str(sample / "houses"), "future": str(sample / "3d-future"), "cache_dir": str(workdir / "cache")}})
    outs = {n: workdir / "ingest" / f"{n}.parquet" for n in OUTPUTS}
    ingest.run(cfg, Files(), Files(outs), shard=0)
    objs = pd.read_parquet(outs["objects"])
    mesh_of, box_models = tables.read_meshes(outs["models"], objs.model_id.dropna())
    pairs = []
    for _, g in objs.groupby("room_id"):
        depth = boxes.penetration_depths(g[["cx", "cy", "cz", "hx", "hy", "hz", "yaw"]].to_numpy())
        poses, mids, cats = g[["px", "py", "pz", "yaw", "sx", "sy", "sz"]].to_numpy(), g.model_id.tolist(), g.category.tolist()
        for i, j in zip(*np.nonzero(np.triu(depth > limit, 1))):
            if mids[i] in mesh_of and mids[j] in mesh_of and not {mids[i], mids[j]} & box_models:
                pairs.append((f"{cats[i]} / {cats[j]}", collision.world_mesh(mesh_of[mids[i]], poses[i]),
                              collision.world_mesh(mesh_of[mids[j]], poses[j])))
    return pairs


def synthetic_pairs(sample: Path) -> list[tuple[str, tuple, tuple]]:
    """Bookshelves whose panels interleave: box panels half a shelf spacing up and 0.4 m across; both on the floor,
    5 and 4 shelves, 0.4 m apart (bottoms and tops coincide in part); a small shelf standing in the big one's bottom
    compartment (boxes overlap, meshes do not); two copies of the real shelf 0.15, 0.05 and 0.15 m apart."""
    from pipeline.corpus.future import _parse_obj

    a, step = bookshelf(), (1.8 - 0.02) / 6
    small = bookshelf(shelves=0, width=0.3, depth=0.25, height=0.2)
    pairs = [("bookshelves interleaved", a, (a[0] + [0.4, 0.0, step / 2], a[1])),
             ("bookshelves 5 and 4 shelves on the floor", a, (bookshelf(4)[0] + [0.4, 0.0, 0.0], bookshelf(4)[1])),
             ("small shelf in a compartment (no contact)", a, (small[0] + [0.0, 0.0, 0.03], small[1]))]
    obj = sample / "3d-future" / "models" / SHELF / "raw_model.obj"
    if obj.exists():
        real = meshes.to_origin_bottom_centre(_parse_obj(obj)[0])
        pairs.append(("real shelf interleaved", real, (real[0] + [0.15, 0.05, 0.15], real[1])))
    return pairs


def main() -> None:
    ap = arguments(__doc__, OUT / "collision")
    ap.add_argument("--sample", type=Path, default=ROOT.parent / "shared" / "data" / "3d-front-meshes")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    cfg, embree = config_mod.validate({}), intersector_class("embree")
    limit = cfg["evaluate"]["collision"]["max_penetration"]
    settings = {name: collision.Measure(**section) for name, section in (
        ("evaluate", cfg["evaluate"]["collision"]["penetration"]), ("instantiate", cfg["instantiate"]["checks"]["penetration"]),
        ("filter", cfg["filter"]["penetration"]))}
    shelf = bookshelf()
    collision.mesh_penetration(shelf, (shelf[0] + 0.1, shelf[1]), embree, settings["evaluate"])  # Embree's device
    result = {"machine": platform.processor() or platform.machine(), "repeat": args.repeat, "limit_m": limit}
    for group, pairs in (("real_pairs", real_pairs(args.sample, args.workdir, limit)), ("thin_parts", synthetic_pairs(args.sample))):
        rows = []
        for label, a, b in pairs:
            row = {"pair": label}
            for name, pen in settings.items():
                for when, p in (("before", replace(pen, surface_spacing=None)), ("after", pen)):
                    row[f"{name}_{when}_m"], row[f"{name}_{when}_ms"] = timed(a, b, embree, p, args.repeat)
            rows.append(row)
        result[group] = summary(pd.DataFrame(rows), limit, list(settings))
    report(result, args.workdir, "collision")


def summary(t: pd.DataFrame, limit: float, names: list[str]) -> dict:
    """Per setting: pairs, mean / median / max ms per pair before and after, pairs deeper than ``limit`` before and
    after, and every pair whose verdict at ``limit`` changed, with its depths (the filter's own limit is 0.15 m:
    its verdicts here are at ``limit`` too)."""
    out = {"pairs": len(t)}
    for n in names:
        for when in ("before", "after"):
            ms = t[f"{n}_{when}_ms"]
            out[f"{n}_{when}"] = {"mean_ms": round(ms.mean(), 1), "median_ms": round(ms.median(), 1),
                                  "max_ms": round(ms.max(), 1), "over_limit": int((t[f"{n}_{when}_m"] > limit).sum())}
        changed = t[(t[f"{n}_before_m"] > limit) != (t[f"{n}_after_m"] > limit)]
        out[f"{n}_changed"] = [f"{r.pair}: {r[f'{n}_before_m']:.4f} -> {r[f'{n}_after_m']:.4f} m"
                               for _, r in changed.iterrows()]
    if len(t) <= 8:  # the hand-made pairs one by one: depth m and ms, before and after
        out["per_pair"] = {r.pair: {n: {"m": [round(r[f"{n}_before_m"], 4), round(r[f"{n}_after_m"], 4)],
                                        "ms": [round(r[f"{n}_before_ms"], 1), round(r[f"{n}_after_ms"], 1)]}
                                    for n in names} for _, r in t.iterrows()}
    return out


if __name__ == "__main__":
    main()
