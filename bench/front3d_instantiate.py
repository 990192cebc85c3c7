"""Re-instantiating the 3D-FRONT mesh sample's rooms (real 3D-FUTURE meshes): each room's own extracted graph
(support and adjacent edges) placed again by the search with the relation-band proposer, no network, then
extracted again: rooms placed, graph consistency, seconds per room.

    .venv/bin/python bench/front3d_instantiate.py [--sample ../shared/data/3d-front-meshes] [--[no-]early-backtrack]
        [--restarts N]

``--[no-]early-backtrack`` and ``--restarts N`` set ``instantiate.early_backtrack`` and ``instantiate.restarts``
(default: the schema's, on and 2).
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from pipeline import config as config_mod, tables
from pipeline.corpus.ingest import OUTPUTS as INGEST_OUTPUTS
from pipeline.placement.reinstantiate import own_plans, reinstantiate, summary
from pipeline.stage import Files
from pipeline.stages import extract_graphs, ingest, symmetry

from common import OUT, ROOT, arguments, report, search_flags, search_overrides, search_suffix


def main() -> None:
    ap = arguments(__doc__, OUT / "front3d_instantiate")
    ap.add_argument("--sample", type=Path, default=ROOT.parent / "shared" / "data" / "3d-front-meshes")
    search_flags(ap)
    args = ap.parse_args()
    w = args.workdir
    cfg = config_mod.validate({"source": "front3d", "shards": 1, "front3d": {
        "houses": str(args.sample / "houses"), "future": str(args.sample / "3d-future"), "cache_dir": str(w / "cache")},
        "instantiate": search_overrides(args)})
    ing = w / "ingest"
    outs = {t: ing / f"{t}-0.parquet" for t in INGEST_OUTPUTS}
    ingest.run(cfg, Files(), Files(outs), shard=0)
    symmetry.run(cfg, Files(models=[outs["models"]]), Files(table=w / "sym.parquet", agreement=w / "sym.json"))
    extract_graphs.run(cfg, Files(rooms=outs["rooms"], architecture=outs["architecture"], objects=outs["objects"],
                                  models=outs["models"], symmetry=w / "sym.parquet"),
                       Files(nodes=w / "nodes.parquet", edges=w / "edges.parquet", summary=w / "extract.json"), shard=0)
    t = {k: pd.read_parquet(outs[k]) for k in ("rooms", "architecture", "objects")}
    meshes, box_models = tables.read_meshes(outs["models"], t["objects"]["model_id"].dropna())
    sym = {r["model_id"]: r["symmetry"] for r in tables.read(w / "sym.parquet", "symmetry").to_pylist()}
    plans = own_plans(pd.read_parquet(w / "nodes.parquet"), pd.read_parquet(w / "edges.parquet"))
    rows = reinstantiate(t, (meshes, box_models, sym), cfg, plans)
    for r in rows:
        print(r["room_id"], r["objects"], "placed" if r["placed"] else r["reason"], f"{r['consistency']:.3f}", f"{r['seconds']:.1f} s")
    ic = cfg["instantiate"]
    report({**summary(rows), "sample": str(args.sample), "early_backtrack": ic["early_backtrack"], "restarts": ic["restarts"]},
           w, "front3d_instantiate" + search_suffix(args))


if __name__ == "__main__":
    main()
