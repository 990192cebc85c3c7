"""Top-down renders per second on one core (geometry/raster.py): real procedural rooms, every channel, at 64 px
over 6.4 m (the CPU default the placement networks will use) and at the paper's 256 px over 6.05 m.

    .venv/bin/python bench/raster.py [--graphs-dir results/graphs/ingested] [--rooms 200]

Reads the final graph nodes of a pipeline run (make pipeline first): architecture segments and object boxes.
"""
from __future__ import annotations

import time

import numpy as np
import pandas as pd

from pipeline.geometry import raster

from common import ROOT, arguments, report


def rooms(nodes: pd.DataFrame, limit: int) -> list[dict]:
    """Per room: walls as segments (from the wall nodes' box and yaw), object boxes and category indices."""
    cats = {c: k for k, c in enumerate(sorted(nodes.loc[nodes.kind == "object", "category"].astype(str).unique()))}
    out = []
    groups = list(nodes.groupby("room_id", sort=True))
    for _, g in groups[::max(1, len(groups) // limit)][:limit]:  # spread over the room types
        w = g[g.kind.astype(str) == "wall"]
        d = np.column_stack([np.cos(w.yaw), np.sin(w.yaw)]) * w.hx.to_numpy()[:, None]
        c = w[["cx", "cy"]].to_numpy()
        seg = np.stack([c - d, c + d], axis=1)
        o = g[g.kind.astype(str) == "object"]
        out.append({"outline": seg[:, 0], "walls": seg, "half": w.hy.to_numpy(), "centre": c.mean(0),
                    "boxes": o[["cx", "cy", "cz", "hx", "hy", "hz", "yaw"]].to_numpy(),
                    "category": o.category.astype(str).map(cats).to_numpy(), "n": len(cats)})
    return out


def rate(rs: list[dict], size: int, mpp: float) -> float:
    start = time.perf_counter()
    for r in rs:
        raster.render_room(raster.Shell(r["outline"], r["walls"], r["half"], {}), r["boxes"], r["category"], r["n"],
                           raster.Canvas(size, mpp, r["centre"]))
    return len(rs) / (time.perf_counter() - start)


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--graphs-dir", default=ROOT / "results" / "graphs" / "ingested")
    ap.add_argument("--rooms", type=int, default=200)
    args = ap.parse_args()
    rs = rooms(pd.read_parquet(f"{args.graphs_dir}/nodes.parquet"), args.rooms)
    report({"rooms": len(rs), "objects_per_room": round(float(np.mean([len(r["boxes"]) for r in rs])), 1),
            "renders_per_s_64px_0.1m": round(rate(rs, 64, 0.1), 1),
            "renders_per_s_256px_paper": round(rate(rs, 256, 6.05 / 256), 1)}, args.workdir, "raster")


if __name__ == "__main__":
    main()
