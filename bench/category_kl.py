"""Category KL at 1,000 generated rooms per room type (ATISS reports <= 0.01 at that size): a benchmark, not the
default run.

    .venv/bin/python bench/category_kl.py [--graphs 1000] [--run .] [--room-types bedroom living ...]

Reads a finished default run under ``--run`` (its trained graph models, final graphs, filtered and ingested shards
and, when present, results/eval/<type>/metrics.json). Placing 1,000 rooms per type would take hours on this
machine, so the 1,000 rooms are the graph model's sampled graphs: a placed room holds exactly its graph's objects
(a scene places all of them or fails), so its category counts are its graph's. What that leaves out, the choice of
which graphs the search manages to place, is measured on the run's own rooms: the KL of the sampled graphs its
default variant tried against the KL of the rooms it placed. The held-out real rooms (p) and the KL (1e-6 smoothing) are those
of ``planit evaluate``; the floor is the same KL between two disjoint sets of real rooms of the held-out size and
as many as the pool leaves for the other (a pool of ~400 rooms per type cannot give 1,000).
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

from pipeline import config as config_mod, tables
from pipeline.evaluation import distributions, scores as evaluate_scores
from pipeline.evaluation.sets import load_real
from pipeline.graphs.files import read_split
from pipeline.stage import Files
from pipeline.stages import sample_graphs

from common import ROOT, arguments, report


def shards(run: Path, pattern: str) -> list[Path]:
    return sorted(run.glob(pattern))


def sampled_categories(cfg: dict, run: Path, room_type: str, graphs: int, tmp: Path) -> tuple[list[list[str]], dict]:
    """Each of ``graphs`` sampled graphs' node categories, and the sampler's summary."""
    g = run / "results" / "graphs" / "ingested"
    out = tmp / room_type
    out.mkdir(parents=True, exist_ok=True)
    summary = sample_graphs.run(cfg, Files(model=run / "results" / "graph_model" / room_type / "planit" / "model.pt",
                                           nodes=g / "nodes.parquet", edges=g / "edges.parquet", spec=None),
                                Files(nodes=out / "nodes.parquet", edges=out / "edges.parquet", summary=out / "summary.json"),
                                room_type=room_type, count=graphs)
    return graph_categories(out / "nodes.parquet"), summary


def graph_categories(nodes: Path, rooms: set[str] | None = None) -> list[list[str]]:
    """Per sampled graph in ``nodes`` (of those in ``rooms``, default all): its object nodes' categories (walls,
    doors and windows are architecture)."""
    df = tables.read(nodes, "generated_nodes").to_pandas()
    keep = (df["kind"].astype(str) == "object") & (df["room_id"].isin(rooms) if rooms is not None else True)
    return [g["category"].astype(str).tolist() for _, g in df[keep].groupby("room_id", sort=False)]


def one_type(cfg: dict, run: Path, room_type: str, graphs: int, tmp: Path) -> dict:
    eps = cfg["evaluate"]["kl_eps"]
    train, real = load_real(room_type, read_split(run / "results" / "splits" / f"{room_type}.parquet"),
                            shards(run, "results/filter/shards/rooms-*.parquet"),
                            shards(run, "results/ingest/shards/architecture-*.parquet"),
                            shards(run, "results/ingest/shards/objects-*.parquet"))
    p = distributions.flatten([r.categories for r in real.rooms])
    rooms, summary = sampled_categories(cfg, run, room_type, graphs, tmp)
    kl = lambda rs: round(distributions.category_kl(p, distributions.flatten(rs), eps), 5)
    floor = evaluate_scores.floors(train, real, len(rooms), cfg["evaluate"], cfg["seed"])["category_kl"]
    value = kl(rooms)
    out = {"heldout_rooms": len(real.rooms), "sampled_graphs": len(rooms), "category_kl": value, "floor": floor,
           "goal_kl_le_0.01": value <= 0.01, "sampler": {k: summary[k] for k in ("written", "failed_after_budget")}}
    metrics = run / "results" / "eval" / room_type / "metrics.json"
    if metrics.exists():  # the run's own graphs: every one the search tried, and the rooms it placed
        placed = json.loads(metrics.read_text())["sets"]["planit"]
        tried = run_graphs(run, room_type)
        out["run"] = {"graphs_tried": len(tried), "graphs_tried_category_kl": kl(tried), "placed": placed["scenes"],
                      "placed_category_kl": placed["category_kl"]}
    return out


def run_graphs(run: Path, room_type: str) -> list[list[str]]:
    """Object categories of the sampled graphs the run's default variant tried to place."""
    scenes = tables.read(run / "results" / "generated" / room_type / "planit" / "scenes.parquet", "scenes",
                         columns=["scene_id"])
    return graph_categories(run / "results" / "graph_model" / room_type / "sampled" / "nodes.parquet",
                            set(scenes.column("scene_id").to_pylist()))


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--graphs", type=int, default=1000)
    ap.add_argument("--run", type=Path, default=ROOT, help="folder of a finished default run")
    ap.add_argument("--room-types", nargs="*", default=None)
    args = ap.parse_args()
    cfg = config_mod.load(ROOT / "config" / "config.yaml")
    types = args.room_types or cfg["graph_model"]["room_types"] or sorted(
        p.parent.name for p in (args.run / "results" / "graph_model").glob("*/model.pt"))
    with tempfile.TemporaryDirectory() as tmp:
        result = {"graphs_per_type": args.graphs, "run": str(args.run.resolve()),
                  "room_types": {t: one_type(cfg, args.run, t, args.graphs, Path(tmp)) for t in types}}
    report(result, args.workdir, f"category_kl-{args.graphs}")


if __name__ == "__main__":
    main()
