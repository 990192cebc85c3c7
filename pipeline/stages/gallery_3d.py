"""The report's 3D gallery of one room type: each method's first placed scenes and the first held-out real rooms in
one viewer page (``pipeline/viewer``), each with its graphs."""
from __future__ import annotations

from pathlib import Path

from .. import methods, tables
from ..errors import InputError
from ..graphs.files import read_split
from ..stage import Files


def _planned(method: str, nodes: list[Path], edges: list[Path]) -> tuple[Path, Path] | None:
    """The sampled graph tables the method placed (those of its graph generator), or None."""
    source = methods.get(method).graphs
    for n, e in zip(nodes, edges):
        if Path(e).parent.parent.name == source:
            return Path(n), Path(e)
    return None


def _placed(scenes: Path, count: int) -> list[str]:
    df = tables.read(scenes, "scenes").to_pandas()
    return df.loc[df["status"].astype(str).isin(tables.SCORED), "scene_id"].astype(str).tolist()[:count]


def run(config: dict, inp: Files, out: Files, room_type: str, threads: int = 1) -> dict:
    from ..viewer import sources
    from ..viewer.page import page

    methods.load_plugins(config["generation"]["plugins"])
    count = config["evaluate"]["gallery"]
    ext = {**config["extract"], "floor_contact": config["floor_contact"]}
    rooms = []
    for scenes in inp.generated_scenes:
        folder = Path(scenes).parent
        planned = _planned(folder.name, inp.sampled_nodes or [], inp.sampled_edges or [])
        rooms += [sources.generated_room(folder, sid, planned, ext) for sid in _placed(Path(scenes), count)]
    shards = {"rooms": inp.rooms, "architecture": inp.architecture, "objects": inp.objects, "models": inp.models}
    held = [r for r, s in sorted(read_split(inp.split).items()) if s == "heldout"][:count]
    rooms += [sources.corpus_room(shards, (inp.nodes, inp.edges), r, str(inp.split), f"{r} (held-out real)")
              for r in held]
    if not rooms:
        raise InputError(f"{inp.split}: no placed scene and no held-out room of '{room_type}' to show")
    html = page(rooms, f"{room_type}: generated and held-out real rooms")
    tables.write_atomic(out.page, lambda tmp: Path(tmp).write_text(html))
    return {"rooms": len(rooms), "megabytes": round(len(html) / 2 ** 20, 2)}
