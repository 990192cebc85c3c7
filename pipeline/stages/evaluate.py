"""Evaluate one room type: every method's rooms and the held-out real rooms scored by the same metrics
(metrics.json, one row per scene, the sets side by side as CSV, and a gallery)."""
from __future__ import annotations

from pathlib import Path

from .. import tables
from ..evaluation.evaluate import evaluate_room_type
from ..evaluation.gallery import gallery
from ..evaluation.pages import evaluation_page, power_figure
from ..evaluation.scores import metrics_table
from ..evaluation.sets import generated_sets, load_real
from ..graphs.files import read_split
from ..html import write_html
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, threads: int = 1) -> dict:
    train, real = load_real(room_type, read_split(inp.split), inp.rooms, inp.architecture, inp.objects)
    gen = generated_sets(inp.summaries, inp.generated_rooms, inp.generated_architecture, inp.generated_objects,
                         inp.generated_scenes)
    meshes, box_models = tables.read_meshes_of(inp.models, {m for rs in (train, real, *gen) for r in rs.rooms
                                                            for m in r.model_ids})
    sym = tables.read(inp.symmetry, "symmetry", columns=["model_id", "symmetry"]).to_pylist()
    metrics, frame = evaluate_room_type(config, room_type, gen, train, real,
                                        (meshes, box_models, {r["model_id"]: r["symmetry"] for r in sym}), threads)
    tables.write(out.scenes, "eval_scenes", tables.from_rows("eval_scenes", tables.records(frame)))
    tables.write_csv(out.table, metrics_table(metrics))
    write_html(out.table_html, evaluation_page(metrics))
    tables.write_figure(out.power, power_figure(metrics), dpi=110)
    gallery(out.gallery, gen[0], Path(inp.generated_archives[0]), real, inp.nodes, inp.edges, config["evaluate"]["gallery"])
    tables.write_json(out.metrics, metrics)
    return {name: s["category_kl"] for name, s in metrics["sets"].items()}
