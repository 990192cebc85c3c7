"""A method's generated rooms of one room type in one format other tools load (USD stages, ProcTHOR-style houses or
3D-FRONT-style houses with their models; docs/formats.md), as one archive."""
from __future__ import annotations

from ..export import export_archive
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, method: str, format: str) -> dict:
    paths = {t: [inp[t]] for t in ("rooms", "architecture", "objects", "models")}
    summary = export_archive(format, paths, out.archive, {**config["export"], "ithor": config["ithor"]})
    return {"room_type": room_type, "method": method, **{k: v for k, v in summary.items() if k != "files"}}
