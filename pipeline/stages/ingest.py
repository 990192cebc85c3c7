"""Ingest stage: a source -> canonical tables ``rooms``, ``architecture``, ``objects``, ``models``,
``ground_truth`` and an ``ingest_report``, under ``results/ingest/``."""
from __future__ import annotations

import logging
from collections import Counter
from pathlib import Path

import pyarrow as pa

from .. import tables
from ..config import config_hash
from ..corpus import procedural
from ..log import progress

log = logging.getLogger("planit.ingest")
OUTPUTS = ("rooms", "architecture", "objects", "models", "ground_truth", "ingest_report")


def ingest_procedural(config: dict) -> dict[str, pa.Table]:
    cfg = config["procedural"]
    seed = config["seed"]
    models, model_rows = procedural.build_models(cfg["variants_per_category"], seed)
    rooms, arch, objs, gt = [], [], [], []
    jobs = [(i, rt) for rt in procedural.ROOM_TYPES for i in range(cfg["rooms"].get(rt, 0))]
    for i, rt in progress(jobs, desc="procedural rooms"):
        r = procedural.generate_room(i, rt, seed, models, cfg["defect_rate"], cfg["l_shape_rate"])
        room, a, o, g = procedural.room_tables(r)
        rooms.append(room)
        arch += a
        objs += o
        gt += g
    used = {o["model_id"] for o in objs}
    model_rows = [m for m in model_rows if m["model_id"] in used]
    per_type = Counter(r["room_type"] for r in rooms)
    cats = Counter(o["category"] for o in objs)
    report = [{"source": "procedural", "item": rt, "kind": "room", "status": "read", "reason": None, "count": n}
              for rt, n in sorted(per_type.items())]
    report += [{"source": "procedural", "item": c, "kind": "category", "status": "found", "reason": None, "count": n}
               for c, n in sorted(cats.items())]
    report.append({"source": "procedural", "item": "models", "kind": "model", "status": "kept", "reason": None,
                   "count": len(model_rows)})
    return {"rooms": tables.from_rows("rooms", rooms), "architecture": tables.from_rows("architecture", arch),
            "objects": tables.from_rows("objects", objs), "models": tables.from_rows("models", model_rows),
            "ground_truth": tables.from_rows("ground_truth", gt), "ingest_report": tables.from_rows("ingest_report", report)}


def _report_rows(source: str, report: Counter) -> list[dict]:
    return [{"source": source, "item": reason, "kind": kind,
             "status": status, "reason": reason, "count": n} for (kind, status, reason), n in sorted(report.items())]


def _tables(rooms, arch, objs, models, gt, report_rows) -> dict[str, pa.Table]:
    return {"rooms": tables.from_rows("rooms", rooms), "architecture": tables.from_rows("architecture", arch),
            "objects": tables.from_rows("objects", objs), "models": tables.from_rows("models", models),
            "ground_truth": tables.from_rows("ground_truth", gt), "ingest_report": tables.from_rows("ingest_report", report_rows)}


def ingest_front3d(config: dict) -> dict[str, pa.Table]:
    from ..corpus import front3d

    cfg = config["front3d"]
    houses_dir, future = Path(cfg["houses"]), Path(cfg["future"])
    if not houses_dir.is_dir():
        raise FileNotFoundError(f"front3d.houses: no such folder '{houses_dir}'")
    if not future.is_dir():
        raise FileNotFoundError(f"front3d.future: no such folder '{future}'")
    opt = lambda key: Path(cfg[key]) if cfg[key] else None  # noqa: E731
    catalogue = front3d.Catalogue.load(future, opt("models_csv"), opt("category_csv"), opt("model_info"))
    cache = front3d.MeshCache(future, opt("cache_dir"))
    files = sorted(houses_dir.glob("*.json"))[: cfg["max_houses"]]
    report: Counter = Counter()
    rooms, arch, objs, models = [], [], [], {}
    for f in progress(files, desc="3D-FRONT houses"):
        try:
            out = front3d.parse_house(f, catalogue, cache, cfg, report)
        except front3d.HouseError as exc:
            log.warning("house skipped: %s", exc)
            report[("house", "skipped", str(exc))] += 1
            continue
        report[("house", "read", "ok")] += 1
        rooms += out["rooms"]
        arch += out["architecture"]
        objs += out["objects"]
        for k, v in out["models"].items():
            models.setdefault(k, v)
    report[("model", "kept", f"meshes parsed {cache.parsed}, from cache {cache.hits}")] += len(models)
    return _tables(rooms, arch, objs, list(models.values()), [], _report_rows("front3d", report))


def ingest_ithor(config: dict) -> dict[str, pa.Table]:
    from ..corpus import ithor

    cfg = config["ithor"]
    data, path = ithor.load(cfg)
    report: Counter = Counter()
    out = {k: [] for k in ("rooms", "architecture", "objects", "models", "ground_truth")}
    for group in cfg["groups"]:
        if group not in data or group not in ithor.GROUPS:
            raise KeyError(f"{path}: no room group '{group}' (ithor.groups; known: {sorted(ithor.GROUPS)})")
        for k, objects in enumerate(progress(data[group], desc=f"AI2-THOR {group}")):
            for name, rows in ithor.parse_room(group, k, objects, cfg, report).items():
                out[name] += rows
    return _tables(out["rooms"], out["architecture"], out["objects"], out["models"], out["ground_truth"],
                   _report_rows("ithor", report))


def ingest_suncg(config: dict) -> dict[str, pa.Table]:
    from ..corpus import front3d, suncg

    cfg = config["suncg"]
    houses = Path(cfg["houses"])
    files = [houses] if houses.is_file() else sorted(houses.glob("*/house.json"))
    if not files:
        raise FileNotFoundError(f"suncg.houses: no house.json under '{houses}'")
    room_folder = Path(cfg["room_folder"]) if cfg["room_folder"] else None
    report: Counter = Counter()
    out = {k: [] for k in ("rooms", "architecture", "objects", "models")}
    for f in progress(files, desc="SUNCG houses"):
        try:
            parsed = suncg.parse_house(f, room_folder, report)
        except front3d.HouseError as exc:
            log.warning("house skipped: %s", exc)
            report[("house", "skipped", str(exc))] += 1
            continue
        report[("house", "read", "ok")] += 1
        for k in out:
            out[k] += parsed[k]
    if not out["rooms"]:
        reasons = "; ".join(r for (kind, status, r) in report if kind == "house" and status == "skipped")
        raise FileNotFoundError(f"source suncg: no room could be read: {reasons}")
    models = {m["model_id"]: m for m in out["models"]}
    return _tables(out["rooms"], out["architecture"], out["objects"], list(models.values()), [],
                   _report_rows("suncg", report))


SOURCES = {"procedural": ingest_procedural, "front3d": ingest_front3d, "ithor": ingest_ithor, "suncg": ingest_suncg}


def run(config: dict, out_dir: str | Path) -> dict[str, int]:
    """Ingest ``config['source']`` and write every canonical table; returns row counts."""
    source = config["source"]
    if source not in SOURCES:
        raise NotImplementedError(f"source '{source}' is not implemented in this version; available: {sorted(SOURCES)}")
    result = SOURCES[source](config)
    out_dir = Path(out_dir)
    section = {"seed": config["seed"], "source": source, source: config.get(source)}
    for name in OUTPUTS:
        tables.write(out_dir / f"{name}.parquet", name, result[name],
                     extra={"source": source, "config_hash": config_hash(section)})
    counts = {name: result[name].num_rows for name in OUTPUTS}
    log.info("ingested %s: %s", source, counts)
    for row in result["ingest_report"].to_pylist():
        log.info("  %-8s %-9s %6d  %s", row["kind"], row["status"], row["count"], row["reason"] or row["item"])
    return counts
