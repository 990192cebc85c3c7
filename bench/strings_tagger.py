"""The string method's edge tagger against the mean-shift bandwidth (issue 31's goal: tagging >= 90% on held-out rooms).
For each room type of a run and each bandwidth scale, the clusters and the tagger are fitted as the train_placement
rule fits them (``strings.tagger``, default preset); the validation accuracy is what a choice may look at, the
held-out accuracy is reported beside it and never used to choose.

    .venv/bin/python bench/strings_tagger.py [--scales 1 1.5 2] [--types bedroom ...]   # reads ./results

Prints a table per room type and scale: clusters, triples with a choice, validation and held-out accuracy (all
edges; edges whose triple has several clusters, and the majority cluster's share there), training seconds."""
from __future__ import annotations

import argparse
import copy
import glob
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pipeline import config as config_mod, tables  # noqa: E402
from pipeline.graphs.files import read_split  # noqa: E402
from pipeline.methods.interface import RoomTypeRows  # noqa: E402
from pipeline.methods.strings.tagfit import fit_tagger  # noqa: E402
from pipeline.room import load_rooms  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scales", type=float, nargs="+", default=[1.0, 1.5, 2.0])
    ap.add_argument("--types", nargs="+", default=None)
    args = ap.parse_args()
    cfg = config_mod.load(ROOT / "config" / "config.yaml")
    res = Path("results")
    types = args.types or sorted(p.parent.name for p in res.glob("placement/*/tagger"))
    nodes_all = tables.read(res / "graphs/ingested/nodes.parquet", "final_nodes").to_pandas()
    edges_all = tables.read(res / "graphs/ingested/edges.parquet", "final_edges").to_pandas()
    shards = {t: sorted(glob.glob(str(res / f"ingest/shards/{t}-*.parquet"))) for t in ("architecture", "objects")}
    rooms = sorted(glob.glob(str(res / "filter/shards/rooms-*.parquet")))
    print("| room type | bandwidth scale | clusters | triples with a choice | validation accuracy (with a choice) | "
          "held-out accuracy (with a choice; majority there) | seconds |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for room_type in types:
        node_df = nodes_all[nodes_all["room_type"].astype(str) == room_type]
        edge_df = edges_all[edges_all["room_id"].isin(set(node_df["room_id"]))]
        _, _, _, inputs = load_rooms(rooms, shards["architecture"], shards["objects"], set(node_df["room_id"]))
        split = read_split(res / "splits" / f"{room_type}.parquet")
        for scale in args.scales:
            c = copy.deepcopy(cfg)
            c["strings"]["tagger"]["bandwidth"] = {k: v * scale if k != "angle" else min(v * scale, 180)
                                                   for k, v in cfg["strings"]["tagger"]["bandwidth"].items()}
            with tempfile.TemporaryDirectory() as tmp:
                fitted = fit_tagger(c, room_type, "tagger", RoomTypeRows(node_df, edge_df, inputs, split), Path(tmp) / "p.pt")
            s, h = fitted.summary, fitted.summary["heldout"]
            best = fitted.history.loc[fitted.history["epoch"] == s["best_epoch"]].iloc[0]
            print(f"| {room_type} | {scale:g} | {s['clusters']} | {s['triples_with_choice']} of {s['triples']} | "
                  f"{best['validation_accuracy']:.3f} ({best['validation_accuracy_with_choice']:.3f}) | "
                  f"{h['accuracy']:.3f} ({h['accuracy_with_choice']:.3f}; {h['majority_with_choice']:.3f}) | "
                  f"{s['train_seconds']} |", flush=True)


if __name__ == "__main__":
    main()
