"""`planit generate` and `planit complete`: the trained models end to end, outside Snakemake. They read the
default workflow's outputs (the paths of rules/common.smk) and write under results/generated/."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from .. import tables
from ..errors import InputError
from ..placement.plan import plans_from_tables
from . import instantiate, sample_graphs

GRAPHS = Path("results/graphs/ingested")


def corpus_paths(config: dict) -> dict:
    """The kept corpus's canonical tables per shard, the symmetry and category-size tables (workflow layout)."""
    shards = range(config["shards"])
    rooms = [Path(f"results/filter/shards/rooms-{k}.parquet") for k in shards]
    if not all(p.exists() for p in rooms):
        raise InputError(f"{rooms[0].parent}: the filter's {config['shards']} shard(s) are not all there; run the "
                         "pipeline first, or give the config it ran with (--config; default config/config.yaml)")
    return {"rooms": rooms,
            **{t: [Path(f"results/ingest/shards/{t}-{k}.parquet") for k in shards] for t in ("architecture", "objects", "models")},
            "symmetry": GRAPHS / "symmetry.parquet", "category_sizes": GRAPHS / "stats" / "category_sizes.parquet"}


def _trained(path: Path, rule: str) -> Path:
    if not path.exists():
        raise InputError(f"{path}: not trained yet; run snakemake {path} (rule {rule}) or the whole pipeline first")
    return path


def generate(config: dict, room_type: str, spec: Path | None, n: int, folder: Path) -> dict:
    """Sample ``n`` graphs (completing ``spec`` when given) and place them; everything lands in ``folder``."""
    model = _trained(Path("results/graph_model") / room_type / "model.pt", "train_graph_model")
    nets = _trained(Path("results/placement") / room_type / "cfcn" / "model.pt", "train_placement")
    graphs = folder / "graphs"
    sample_graphs.run(config, room_type, model, GRAPHS / "nodes.parquet", GRAPHS / "edges.parquet",
                      graphs / "nodes.parquet", graphs / "edges.parquet", graphs / "summary.json", spec, n)
    p = corpus_paths(config)
    return instantiate.run(config, room_type, "planit", graphs / "nodes.parquet", graphs / "edges.parquet", nets, p["rooms"],
                           p["architecture"], p["objects"], p["models"], p["symmetry"], p["category_sizes"], folder, n)


def complete(config: dict, room: str, keep: int, folder: Path | None) -> dict:
    """Keep the first ``keep`` objects (of the placement order) of a real room and place the rest of its graph."""
    import torch

    torch.set_num_threads(1)
    flt = [("room_id", "=", room)]
    nodes = tables.read(GRAPHS / "nodes.parquet", "final_nodes", filters=flt).to_pandas()
    if nodes.empty:
        raise InputError(f"{GRAPHS / 'nodes.parquet'}: no room '{room}' among the kept rooms' graphs")
    edges = tables.read(GRAPHS / "edges.parquet", "final_edges", filters=flt).to_pandas()
    room_type = str(nodes["room_type"].iloc[0])
    plan = replace(plans_from_tables(nodes, edges)[0], scene_id=f"{room}_completed")
    if not 0 <= keep <= len(plan.ids):
        raise InputError(f"--keep: {keep}, but room {room} has {len(plan.ids)} objects")
    from ..learning import checkpoint
    from ..methods.planit.nets.train import KIND

    saved = checkpoint.load(_trained(Path("results/placement") / room_type / "cfcn" / "model.pt", "train_placement"), KIND)
    p = corpus_paths(config)
    ctx = instantiate.load_context(config, room_type, saved, p["rooms"], p["architecture"], p["objects"], p["models"],
                                   p["symmetry"], p["category_sizes"])
    proposer = instantiate.make_proposer("cfcn", saved, config["instantiate"])
    variant = config["instantiate"]["variants"]["heldout"]
    folder = folder or Path("results/generated") / room_type / f"complete_{room}"
    return instantiate.write_outputs(config, ctx, [plan], proposer, variant, "complete", folder, keep)
