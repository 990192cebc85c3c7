"""Ingest one shard of a source: canonical tables ``rooms``, ``architecture``, ``objects``, ``models``,
``ground_truth``, an ``ingest_report`` and the ``drops`` of the rooms of that shard.

Procedural rooms are generated only in their own shard (``shard_of(room_id)``: each room is seeded by
``(seed, room type, index)`` alone, so a shard's rooms do not depend on the others); real houses and SUNCG
files go to ``shard_of(file name)``; AI2-THOR rooms to ``shard_of(room_id)``.
"""
from __future__ import annotations

import logging
from collections import Counter
from pathlib import Path

import pyarrow as pa

from .. import tables
from ..errors import InputError
from ..log import progress
from ..shards import shard_of
from . import procedural
from .ledger import Ledger

log = logging.getLogger("planit.ingest")
OUTPUTS = ("rooms", "architecture", "objects", "models", "ground_truth", "ingest_report", "drops")


def _tables(rooms, arch, objs, models, gt, ledger: Ledger, shard: int) -> dict[str, pa.Table]:
    for r in rooms:
        r["shard"] = shard
    report = [{"source": ledger.source, "item": reason, "kind": kind, "status": status, "reason": reason, "count": n}
              for (kind, status, reason), n in sorted(ledger.items())]
    report += [{"source": ledger.source, "item": uid, "kind": "house", "status": "uid", "reason": str(file), "count": 1}
               for uid, file in sorted(ledger.houses)]
    return {"rooms": tables.from_rows("rooms", rooms), "architecture": tables.from_rows("architecture", arch),
            "objects": tables.from_rows("objects", objs), "models": tables.from_rows("models", models),
            "ground_truth": tables.from_rows("ground_truth", gt), "ingest_report": tables.from_rows("ingest_report", report),
            "drops": tables.from_rows("drops", ledger.drops)}


def ingest_procedural(config: dict, shard: int, shards: int) -> dict[str, pa.Table]:
    cfg, seed = config["procedural"], config["seed"]
    jobs = [(i, rt) for rt in procedural.ROOM_TYPES for i in range(cfg["rooms"].get(rt, 0))
            if shard_of(procedural.room_id(rt, i), shards) == shard]
    models, model_rows = procedural.build_models(cfg["variants_per_category"], seed)
    rooms, arch, objs, gt = [], [], [], []
    for i, rt in progress(jobs, desc=f"procedural rooms, shard {shard}"):
        r = procedural.generate_room(i, rt, seed, models, cfg["defect_rate"], cfg["l_shape_rate"],
                                       cfg["placement"])
        room, a, o, g = procedural.room_tables(r)
        rooms.append(room)
        arch += a
        objs += o
        gt += g
    used = {o["model_id"] for o in objs}
    ledger = Ledger("procedural")
    ledger.update({("room", "read", rt): n for rt, n in Counter(r["room_type"] for r in rooms).items()})
    ledger.update({("category", "found", c): n for c, n in Counter(o["category"] for o in objs).items()})
    return _tables(rooms, arch, objs, [m for m in model_rows if m["model_id"] in used], gt, ledger, shard)


def _house_files(folder: Path, pattern: str, key: str, limit: int | None, shard: int, shards: int) -> list[Path]:
    """This shard's files among the first ``limit`` matches of ``pattern`` (sorted), by file name."""
    if not folder.exists():
        raise InputError(f"{key}: no such file or folder '{folder}'")
    files = [folder] if folder.is_file() else sorted(folder.glob(pattern))[:limit]
    return [f for f in files if shard_of(f.name if f.name != "house.json" else f.parent.name, shards) == shard]


def ingest_front3d(config: dict, shard: int, shards: int) -> dict[str, pa.Table]:
    from . import front3d

    cfg = config["front3d"]
    files = _house_files(Path(cfg["houses"]), "*.json", "front3d.houses", cfg["max_houses"], shard, shards)
    future = Path(cfg["future"])
    if not future.is_dir():
        raise InputError(f"front3d.future: no such folder '{future}'")
    opt = lambda key: Path(cfg[key]) if cfg[key] else None  # noqa: E731
    future_models = front3d.FutureModels.load(future, opt("models_csv"), opt("category_csv"), opt("model_info"))
    ledger = Ledger("front3d")
    ctx = front3d.Context(future_models, front3d.MeshCache(future, opt("cache_dir")), cfg, ledger, {})
    out = {"rooms": [], "architecture": [], "objects": []}
    for f in progress(files, desc=f"3D-FRONT houses, shard {shard}"):
        _house(front3d.parse_house, (f, ctx), f, out, ledger)
    ledger[("model", "parsed", "OBJ meshes parsed")] += ctx.meshes.parsed
    ledger[("model", "cached", "OBJ meshes read from the cache")] += ctx.meshes.hits
    models = [m for m in ctx.models.values() if m is not None]
    return _tables(out["rooms"], out["architecture"], out["objects"], models, [], ledger, shard)


def _house(parse, args: tuple, file: Path, out: dict, ledger: Ledger) -> None:
    """Parse one house into ``out`` inside its own error boundary: whatever goes wrong skips this house, recorded
    with its file (and the JSON path of the field, where the reader names one); the run goes on."""
    from .front3d import HouseError

    try:
        parsed = parse(*args)
    except HouseError as exc:
        log.warning("house skipped: %s", exc)
        ledger.drop("house", f"{exc.path}: {exc.reason}" if exc.path else exc.reason, file=file, field=exc.path or None,
                    status="skipped")
        return
    except Exception as exc:  # noqa: BLE001 - the boundary: one odd house never stops the run (traceback logged)
        log.warning("house skipped: %s: unexpected %s: %s", file, type(exc).__name__, exc, exc_info=True)
        ledger.drop("house", f"unexpected {type(exc).__name__}: {exc}", file=file, status="skipped")
        return
    ledger[("house", "read", "ok")] += 1
    if parsed.get("house_id"):
        ledger.houses.append((parsed.pop("house_id"), str(file)))
    for k, rows in parsed.items():
        if isinstance(out[k], dict):  # models, by id: the first house to use a model defines its row
            for row in rows:
                out[k].setdefault(row["model_id"], row)
        else:
            out[k] += rows


def ingest_ithor(config: dict, shard: int, shards: int) -> dict[str, pa.Table]:
    from . import ithor

    cfg = config["ithor"]
    data, path = ithor.load(cfg)
    ledger = Ledger("ithor")
    out = {k: [] for k in ("rooms", "architecture", "objects", "models", "ground_truth")}
    for group in cfg["groups"]:
        if group not in data or group not in ithor.GROUPS:
            raise InputError(f"{path}: no room group '{group}' (ithor.groups; known: {sorted(ithor.GROUPS)})")
        mine = [(k, objects) for k, objects in enumerate(data[group]) if shard_of(ithor.room_id(group, k), shards) == shard]
        for k, objects in progress(mine, desc=f"AI2-THOR {group}, shard {shard}"):
            for name, rows in ithor.parse_room(group, k, objects, cfg, ledger).items():
                out[name] += rows
    return _tables(out["rooms"], out["architecture"], out["objects"], out["models"], out["ground_truth"], ledger, shard)


def ingest_suncg(config: dict, shard: int, shards: int) -> dict[str, pa.Table]:
    from . import suncg

    cfg = config["suncg"]
    files = _house_files(Path(cfg["houses"]), "*/house.json", "suncg.houses", None, shard, shards)
    room_folder = Path(cfg["room_folder"]) if cfg["room_folder"] else None
    ledger = Ledger("suncg")
    out = {"rooms": [], "architecture": [], "objects": [], "models": {}}
    for f in progress(files, desc=f"SUNCG houses, shard {shard}"):
        _house(suncg.parse_house, (f, room_folder, ledger), f, out, ledger)
    if files and not out["rooms"]:
        reasons = "; ".join(f"{d['file']}: {d['field'] + ': ' if d['field'] else ''}{d['reason']}"
                            for d in ledger.drops if d["level"] == "house")
        raise InputError(f"source suncg: no room could be read: {reasons}")
    return _tables(out["rooms"], out["architecture"], out["objects"], list(out["models"].values()), [], ledger, shard)


SOURCES = {"procedural": ingest_procedural, "front3d": ingest_front3d, "ithor": ingest_ithor, "suncg": ingest_suncg}


def ingest_shard(config: dict, shard: int) -> dict[str, pa.Table]:
    """Every table of :data:`OUTPUTS` for shard ``shard`` of ``config['source']``."""
    source, shards = config["source"], config["shards"]
    if not 0 <= shard < shards:
        raise InputError(f"--shard {shard}: not in [0, {shards})")
    return SOURCES[source](config, shard, shards)
