"""PlanIT's Table 3 of one room type: one row per instantiation variant's summary (CSV, and HTML for the report)."""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from .. import tables
from ..errors import InputError
from ..html import write_table_html
from ..stage import Files

TABLE3_COLUMNS = ["variant", "location", "scenes", "placed", "failed", "rejections_per_scene", "backtracks_per_insertion",
                  "violation", "consistency", "relaxed_share", "collision_rate", "median_seconds",
                  "unplanned_adjacent_per_scene", "heldout_pose_loglik"]


def run(config: dict, inp: Files, out: Files) -> pd.DataFrame:
    """One row per variant's summary.json (PlanIT's Table 3 and our consistency), written as CSV and HTML."""
    rows = [_read(p, "instantiate") for p in inp.summaries]
    nets = {s["net"]: s.get("heldout_pose_loglik") for s in (_read(p, "train_placement") for p in inp.nets or [])}
    for r in rows:
        r["heldout_pose_loglik"] = nets.get("fcn" if r.get("location") == "fcn" else "cfcn")
    frame = pd.DataFrame(rows).reindex(columns=["room_type", *TABLE3_COLUMNS])
    tables.write_csv(out.table, frame)
    room_type = ", ".join(frame["room_type"].dropna().astype(str).unique())
    write_table_html(out.table_html, frame, f"Table 3: {room_type}",
                     f"Held-out rooms' own graphs placed by the full method and each ablation (paper_cfcn, paper_fcn: "
                     f"the paper's own search, no relation bands, no snapping); heldout_pose_loglik: the log-likelihood "
                     f"of held-out rooms' true poses under the variant's networks (nats per object). The same rows are "
                     f"in {out.table.name}.")
    return frame


def _read(path, rule: str) -> dict:
    try:
        return json.loads(Path(path).read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: not a readable summary ({exc}); rerun snakemake --forcerun {rule}") from exc
