"""Extraction speed: rays/s and rooms/s with Embree on the default procedural corpus, and with trimesh's
pure-Python backend on a few of the same rooms in the same run (the ratio).

    .venv/bin/python bench/extraction.py [--workdir bench/out] [--rooms 1000] [--python-rooms 4]

Builds the default corpus (config/config.yaml) under --workdir if it is not there yet.
"""
from __future__ import annotations

import platform
import time
import warnings
from pathlib import Path

from pipeline.extraction import extract_room
from pipeline.geometry.raycast import intersector_class
from pipeline.room import room_inputs
from pipeline.stage import Files
from pipeline.stages import symmetry
from pipeline.stages.extract_graphs import load_shard

from common import arguments, default_config, ingest_and_filter, report, shard_paths


def corpus(workdir: Path, cfg: dict) -> dict[str, Path]:
    p = shard_paths(workdir)
    if not p["kept"].exists():
        ingest_and_filter(cfg, p)
    if not p["symmetry"].exists():
        symmetry.run(cfg, Files(models=[p["models"]]), Files(table=p["symmetry"], agreement=p["agreement"]))
    return p


def run(workdir: Path, rooms_wanted: int, python_rooms: int) -> dict:
    cfg = default_config()
    p = corpus(workdir, cfg)
    rooms, arch, objs, models, _ = load_shard(p["kept"], p["architecture"], p["objects"], p["models"])
    inputs = list(room_inputs(rooms, arch, objs))[:rooms_wanted]
    sym = lambda c, m: ("none", "default")  # noqa: E731  symmetry does not change the ray work
    ex = {**cfg["extract"], "floor_contact": cfg["floor_contact"]}
    result = {"rooms": len(inputs), "objects": int(sum(len(r.object_ids) for r in inputs)),
              "machine": f"{platform.processor() or platform.machine()}, 1 core (single process)"}
    embree = intersector_class("embree")
    extract_room(inputs[0], models.get, sym, ex, embree)  # warm-up
    t, rays = time.perf_counter(), 0
    for r in inputs:
        rays += extract_room(r, models.get, sym, ex, embree).rays
    dt = time.perf_counter() - t
    result["embree"] = {"seconds": round(dt, 3), "rooms_per_s": round(len(inputs) / dt, 1), "rays": rays,
                        "rays_per_s": round(rays / dt)}
    subset = inputs[:python_rooms]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        slow = intersector_class("python")
    t_fast = time.perf_counter()
    for r in subset:
        extract_room(r, models.get, sym, ex, embree)
    t_fast = time.perf_counter() - t_fast
    t, rays = time.perf_counter(), 0
    for r in subset:
        rays += extract_room(r, models.get, sym, ex, slow).rays
    dt = time.perf_counter() - t
    result["python"] = {"rooms": len(subset), "seconds": round(dt, 3), "rooms_per_s": round(len(subset) / dt, 3),
                        "rays_per_s": round(rays / dt), "slowdown_vs_embree_same_rooms": round(dt / t_fast, 1)}
    result["ray_kernel"] = kernel(inputs[0], models, ex, embree, slow)
    return result


def kernel(room, models, ex, embree, slow, rays: int = 20000) -> dict:
    """Rays/s of the two backends alone: the first hits of the same random horizontal and downward rays
    against the same room scene (object meshes + plan prisms)."""
    import numpy as np

    from pipeline.geometry.meshes import combine, transform

    parts = [(transform(models[m][0], p[0:3], p[3], p[4:7]), models[m][1]) for m, p in zip(room.model_ids, room.poses)]
    v, f = combine(parts)
    import trimesh

    mesh = trimesh.Trimesh(vertices=v, faces=f, process=False)
    rng = np.random.default_rng(0)
    lo, hi = room.outline.min(axis=0), room.outline.max(axis=0)
    origins = np.column_stack([rng.uniform(lo[0], hi[0], rays), rng.uniform(lo[1], hi[1], rays), rng.uniform(0.05, 1.5, rays)])
    dirs = rng.normal(size=(rays, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    out = {"triangles": int(len(f)), "rays": rays}
    for name, cls in (("embree", embree), ("python", slow)):
        n = rays if name == "embree" else rays // 20
        t = time.perf_counter()
        cls(mesh).intersects_first(ray_origins=origins[:n], ray_directions=dirs[:n])
        out[f"{name}_rays_per_s"] = round(n / (time.perf_counter() - t))
    out["ratio"] = round(out["embree_rays_per_s"] / out["python_rays_per_s"], 1)
    return out


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--rooms", type=int, default=1000)
    ap.add_argument("--python-rooms", type=int, default=4)
    args = ap.parse_args()
    result = run(args.workdir, args.rooms, args.python_rooms)
    report(result, args.workdir, "extraction")


if __name__ == "__main__":
    main()
