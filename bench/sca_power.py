"""The classifier's power on known-bad rooms (issue 27), one setting at a time: the same ``evaluation.sca.sca`` the
evaluate stage runs, on a finished run's held-out rooms of one room type, for the perturbations, the real-vs-real
control and any method's generated rooms. The sweep behind docs/benchmarks.md ("An evaluation that can fail"):

    .venv/bin/python bench/sca_power.py RUN TYPE [--steps 1000 --width 16 --stride 2 --lr 0.002] [--mpp 0.1]
        [--patience 3 --check-every 100 --validation 0.2]
        [--only placement,turns,real_vs_real,planit] [--mode per_set|shared]

RUN: a run directory (``snakemake --directory RUN``) with results/splits, filter and ingest shards and
results/generated/<TYPE>/<method>/. ``--mpp``: a fixed m per pixel instead of fitting each room to the window.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from pipeline import config as config_mod
from pipeline.evaluation import power, render
from pipeline.evaluation.sca import sca, sca_all
from pipeline.evaluation.sets import generated_sets, load_real
from pipeline.graphs.files import read_split


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", type=Path)
    ap.add_argument("room_type")
    knobs = (("steps", int), ("width", int), ("stride", int), ("lr", float), ("patience", int), ("check_every", int),
             ("validation", float))
    for key, kind in knobs:
        ap.add_argument(f"--{key.replace('_', '-')}", dest=key, type=kind)
    ap.add_argument("--mode", choices=["per_set", "shared"], default="per_set",
                    help="per_set: a classifier per set, timed one by one; shared: one per fold for all sets")
    ap.add_argument("--mpp", type=float, help="fixed m per pixel (default: each room fitted to the window)")
    ap.add_argument("--only", help="comma-separated set names (default: every power set, the control, every method)")
    args = ap.parse_args()
    cfg = config_mod.validate({"seed": 0})
    ev = cfg["evaluate"]
    sca_cfg = {**ev["sca"], **{k: getattr(args, k) for k, _ in knobs if getattr(args, k) is not None}}
    res = args.run / "results"
    shards = lambda pattern: sorted(res.glob(pattern))
    train, real = load_real(args.room_type, read_split(res / f"splits/{args.room_type}.parquet"),
                            shards("filter/shards/rooms-*.parquet"), shards("ingest/shards/architecture-*.parquet"),
                            shards("ingest/shards/objects-*.parquet"))
    folders = sorted(p for p in (res / "generated" / args.room_type).iterdir() if (p / "scenes.parquet").exists()
                     and p.name in cfg["generation"]["methods"] and (not args.only or p.name in args.only.split(",")))
    gen = generated_sets(*([p / n for p in folders] for n in ("summary.json", "rooms.parquet", "architecture.parquet",
                                                              "objects.parquet", "scenes.parquet")))
    index = {c: k for k, c in enumerate(sorted({c for s in (train, real, *gen) for r in s.rooms for c in r.categories}))}
    colours = render.palette(sorted(index))
    rcfg = ev["render"]
    draw = (lambda rooms: render.classifier_images(rooms, index, colours, rcfg)) if args.mpp is None else (
        lambda rooms: render.classifier_rgb(np.stack([render.classifier_map(r, index, rcfg["size"], args.mpp,
                                                                            rcfg["front"]) for r in rooms]), colours))
    train_images, real_test = draw(train.rooms), draw(real.rooms)
    own = np.arange(len(real.rooms))
    sets = {n: (draw(rooms), g, own) for n, (rooms, g) in power.power_sets(real.rooms, ev["power"], cfg["seed"]).items()}
    sets |= {rs.name: (draw(rs.rooms), np.arange(len(rs.rooms)), None) for rs in gen}
    kept, back = power.control_split(len(train.rooms), max([len(rs.rooms) for rs in gen] + [len(real.rooms)]),
                                     cfg["seed"])
    sets[power.CONTROL] = (train_images[back], np.arange(len(back)), None)
    only = args.only.split(",") if args.only else list(sets)
    print(f"{args.room_type}: {len(train.rooms)} training, {len(real.rooms)} held-out rooms; {sca_cfg}")
    if args.mode == "shared":  # every set (and the control) in one classifier per fold, as the evaluate stage does
        start = time.perf_counter()
        picked = {n: sets[n] for n in only if n != power.CONTROL}
        outs = sca_all((train_images, real_test), picked, (train_images[kept], sets[power.CONTROL][0], power.CONTROL),
                       {**sca_cfg, "mode": "shared"}, 1, cfg["seed"])
        for name, out in outs.items():
            print(f"{name:24s} {out['accuracy']:6.1f} [{out['low']:.1f}, {out['high']:.1f}] test {out['test']}")
        print(f"shared: {time.perf_counter() - start:.1f} s for {len(outs)} sets", flush=True)
        return
    for name in only:
        images, groups, real_groups = sets[name]
        start = time.perf_counter()
        reference = train_images[kept] if name == power.CONTROL else train_images
        out = sca(reference, real_test, images, groups, sca_cfg, cfg["seed"], real_groups)
        print(f"{name:24s} {out['accuracy']:6.1f} [{out['low']:.1f}, {out['high']:.1f}] test {out['test']} "
              f"{time.perf_counter() - start:.1f} s", flush=True)


if __name__ == "__main__":
    main()
