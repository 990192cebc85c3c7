"""The ``planit`` command line: one subcommand per pipeline stage (each Snakemake rule calls one) and ``stats``.

Every stage command takes files, never folders: its inputs and outputs are exactly the rule's ``{input}`` and
``{output}``. Domain errors (a bad table, config, input file or missing backend) end in one line naming the
file and field, exit code 2; anything else is a bug and keeps its traceback.
"""
from __future__ import annotations

import json
import logging
import os
import sys
from pathlib import Path
from typing import List, Optional

import typer

from . import config as config_mod
from .errors import PlanitError
from .log import setup

app = typer.Typer(add_completion=False, no_args_is_help=True, help=__doc__, pretty_exceptions_enable=False)
log = logging.getLogger("planit")

ConfigOpt = typer.Option(None, "--config", "-c", help="YAML config (validated against the package's schema.yaml)")
JsonOpt = typer.Option(None, "--config-json", help="JSON object merged over the config (the Snakemake rules pass the keys they read)")
ShardOpt = typer.Option(..., "--shard", help="shard index")


def _file(flag: str, help: str = "") -> typer.Option:
    return typer.Option(..., flag, help=help)


def _files(flag: str, help: str = "repeat for every shard") -> typer.Option:
    return typer.Option(..., flag, help=help)


def _fail(message: str) -> None:
    log.error(message)
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code=2)


def _guard(fn, *args, **kwargs):
    """Run a stage; a domain error becomes a one-line message and exit code 2."""
    try:
        return fn(*args, **kwargs)
    except PlanitError as exc:
        _fail(str(exc))


def _stage(fn, config: Optional[Path], overrides: Optional[str], *args):
    """Load and validate the config, then run a stage function on it (guarded). With ``PLANIT_STRICT_KEYS=1`` (the
    Snakemake rules set it) the stage sees only the keys given in ``--config-json``, so a rule whose params miss a
    key its stage reads fails loudly instead of silently reading the default."""
    def run():
        cfg = config_mod.load(config, overrides)
        if os.environ.get("PLANIT_STRICT_KEYS") == "1" and overrides:
            cfg = config_mod.restrict(cfg, json.loads(overrides))
        return fn(cfg, *args)

    return _guard(run)


def _summary(values: dict, skip: tuple[str, ...] = ()) -> None:
    """One line of key=value pairs: what a stage did."""
    typer.echo(" ".join(f"{k}={v}" for k, v in values.items() if k not in skip))


@app.callback()
def main(verbose: bool = typer.Option(False, "--verbose", "-v")) -> None:
    setup(verbose)


@app.command()
def ingest(shard: int = ShardOpt, config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
           rooms: Path = _file("--rooms"), architecture: Path = _file("--architecture"), objects: Path = _file("--objects"),
           models: Path = _file("--models"), ground_truth: Path = _file("--ground-truth"),
           report: Path = _file("--report", "the shard's ingest report"),
           drops: Path = _file("--drops", "one row per dropped house, room, object or model")) -> None:
    """Read one shard of the configured source into canonical tables."""
    from .stages import ingest as stage

    outs = {"rooms": rooms, "architecture": architecture, "objects": objects, "models": models,
            "ground_truth": ground_truth, "ingest_report": report, "drops": drops}
    _summary(_stage(stage.run, config, config_json, shard, outs))


@app.command("ingest-summary")
def ingest_summary(rooms: List[Path] = _files("--rooms"), objects: List[Path] = _files("--objects"),
                   models: List[Path] = _files("--models"), report: List[Path] = _files("--report"),
                   drops: List[Path] = _files("--drops"), out_counts: Path = _file("--out-counts"),
                   out_report: Path = _file("--out-report"), out_drops: Path = _file("--out-drops")) -> None:
    """Gather the ingest shards: category counts for the filter, the summed ingest report, every drop."""
    from .stages import ingest_summary as stage

    _summary(_guard(stage.run, rooms, objects, models, report, drops, out_counts, out_report, out_drops))


@app.command("filter")
def filter_(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
            rooms: Path = _file("--rooms"), architecture: Path = _file("--architecture"),
            objects: Path = _file("--objects"), models: Path = _file("--models"),
            counts: Path = _file("--counts", "category_counts.parquet"),
            out_rooms: Path = _file("--out-rooms"), out_report: Path = _file("--out-report")) -> None:
    """Filter one shard's rooms (every rejection has a reason; interpenetration measured on the meshes)."""
    from .stages import filter_rooms as stage

    _summary(_stage(stage.run, config, config_json, rooms, architecture, objects, models, counts, out_rooms,
                    out_report))


@app.command("filter-report")
def filter_report(report: List[Path] = _files("--report"), out_report: Path = _file("--out-report"),
                  out_counts: Path = _file("--out-counts", "rule_counts.tsv")) -> None:
    """Gather the filter reports; print rooms per room type and outcome."""
    from .stages import filter_report as stage

    typer.echo(_guard(stage.run, report, out_report, out_counts).to_string(index=False))


@app.command()
def symmetry(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
             models: List[Path] = _files("--models"), out_table: Path = _file("--out-table"),
             out_agreement: Path = _file("--out-agreement")) -> None:
    """Assign a functional symmetry type to every model (config table, else detected from the mesh)."""
    from .stages import symmetry as stage

    s = _stage(stage.run, config, config_json, models, out_table, out_agreement)
    typer.echo(f"models={s['models']} agreement={s['agreement']} ({s['agree']}/{s['compared']})")


@app.command()
def extract(shard: int = ShardOpt, config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
            rooms: Path = _file("--rooms", "the shard's kept rooms"), architecture: Path = _file("--architecture"),
            objects: Path = _file("--objects"), models: Path = _file("--models"), symmetry: Path = _file("--symmetry"),
            out_nodes: Path = _file("--out-nodes"), out_edges: Path = _file("--out-edges"),
            out_summary: Path = _file("--out-summary")) -> None:
    """Ray-cast one shard's rooms into raw relation graphs (nodes, edges)."""
    from .stages import extract_graphs as stage

    _summary(_stage(stage.run, config, config_json, shard, rooms, architecture, objects, models, symmetry,
                    out_nodes, out_edges, out_summary))


@app.command("shard-stats")
def shard_stats(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                nodes: Path = _file("--nodes"), edges: Path = _file("--edges"), out_counts: Path = _file("--out-counts"),
                out_candidates: Path = _file("--out-candidates")) -> None:
    """One shard's partial counts and superstructure candidates (the map step of the statistics)."""
    from .stages import shard_statistics as stage

    _summary(_stage(stage.run, config, config_json, nodes, edges, out_counts, out_candidates))


@app.command("graph-stats")
def graph_stats(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                partial: List[Path] = _files("--partial"), nodes: List[Path] = _files("--nodes"),
                out_cooccurrence: Path = _file("--out-cooccurrence"), out_relations: Path = _file("--out-relations"),
                out_hub_patterns: Path = _file("--out-hub-patterns"),
                out_category_sizes: Path = _file("--out-category-sizes")) -> None:
    """Dataset-wide statistics: the shards' partial counts summed, hub patterns accepted, category sizes."""
    from .stages import graph_statistics as stage

    outs = {"cooccurrence": out_cooccurrence, "relations": out_relations, "hub_patterns": out_hub_patterns,
            "category_sizes": out_category_sizes}
    _summary(_stage(stage.run, config, config_json, partial, nodes, outs))


@app.command()
def refine(shard: int = ShardOpt, config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
           nodes: Path = _file("--nodes"), edges: Path = _file("--edges"), candidates: Path = _file("--candidates"),
           relations: Path = _file("--relations"), hub_patterns: Path = _file("--hub-patterns"),
           category_sizes: Path = _file("--category-sizes"), out_nodes: Path = _file("--out-nodes"),
           out_edges: Path = _file("--out-edges"), out_superstructures: Path = _file("--out-superstructures"),
           out_summary: Path = _file("--out-summary")) -> None:
    """Superstructures, pruning and connectivity repair for one shard's raw graphs."""
    from .stages import refine_graphs as stage

    stats = {"relations": relations, "hub_patterns": hub_patterns, "category_sizes": category_sizes}
    outs = {"nodes": out_nodes, "edges": out_edges, "superstructures": out_superstructures, "summary": out_summary}
    _summary(_stage(stage.run, config, config_json, shard, nodes, edges, candidates, stats, outs), skip=("cyclic_room_ids",))


@app.command("gather-graphs")
def gather_graphs(nodes: List[Path] = _files("--nodes"), edges: List[Path] = _files("--edges"),
                  superstructures: List[Path] = _files("--superstructures"), out_nodes: Path = _file("--out-nodes"),
                  out_edges: Path = _file("--out-edges"), out_superstructures: Path = _file("--out-superstructures")) -> None:
    """Concatenate the refined shards into one nodes, edges and superstructures table."""
    from .stages import gather_graphs as stage

    outs = {"nodes": out_nodes, "edges": out_edges, "superstructures": out_superstructures}
    _summary(_guard(stage.run, {"nodes": nodes, "edges": edges, "superstructures": superstructures}, outs))


@app.command()
def score(nodes: List[Path] = _files("--nodes"), edges: List[Path] = _files("--edges"),
          ground_truth: List[Path] = _files("--ground-truth"), out: Path = _file("--out", "metrics JSON")) -> None:
    """Score raw graphs against the corpus's ground truth (support parents, intended adjacencies)."""
    from .stages import score_extraction as stage

    for key, value in _guard(stage.run, nodes, edges, ground_truth, out).items():
        typer.echo(f"{key}: {value}")


@app.command("score-graphs")
def score_graphs(nodes: Path = _file("--nodes"), superstructures: Path = _file("--superstructures"),
                 ground_truth: List[Path] = _files("--ground-truth"), out: Path = _file("--out", "metrics JSON")) -> None:
    """Hub and chain precision / recall against the corpus's ground truth."""
    from .stages import score_superstructures as stage

    for key, value in _guard(stage.run, nodes, superstructures, ground_truth, out).items():
        typer.echo(f"{key}: {value}")


@app.command("graph-report")
def graph_report(nodes: Path = _file("--nodes"), edges: Path = _file("--edges"),
                 superstructures: Path = _file("--superstructures"), out_table1: Path = _file("--out-table1"),
                 out_pruning: Path = _file("--out-pruning"), out_relations: Path = _file("--out-relations"),
                 out_plot: Path = _file("--out-plot")) -> None:
    """Write the graph report: Table 1, pruning by rule, frequent relations (CSV) and a PNG."""
    from .stages import graph_report as stage

    outs = {"table1": out_table1, "pruning": out_pruning, "relations": out_relations, "plot": out_plot}
    _summary(_guard(stage.run, nodes, edges, superstructures, outs))


@app.command("train-graph-model")
def train_graph_model(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                      room_type: str = typer.Option(..., "--room-type"), nodes: Path = _file("--nodes", "final nodes"),
                      edges: Path = _file("--edges", "final edges"), out_model: Path = _file("--out-model"),
                      out_history: Path = _file("--out-history", "loss per epoch (CSV)"),
                      out_curve: Path = _file("--out-curve", "loss curves (PNG)"),
                      out_summary: Path = _file("--out-summary", "training summary (JSON)"),
                      threads: int = typer.Option(1, "--threads", help="CPU threads (the rule's threads)")) -> None:
    """Train the graph generative model of one room type (resumes from the checkpoint beside --out-model)."""
    from .stages import train_graph_model as stage

    _summary(_stage(stage.run, config, config_json, room_type, nodes, edges, out_model, out_history, out_curve,
                    out_summary, threads), skip=("preset",))


@app.command("sample-graphs")
def sample_graphs(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                  room_type: Optional[str] = typer.Option(None, "--room-type", help="default: the spec's room_type"),
                  model: Optional[Path] = typer.Option(None, "--model", help="default: results/graph_model/<type>/model.pt"),
                  nodes: Path = typer.Option(Path("results/graphs/ingested/nodes.parquet"), "--nodes"),
                  edges: Path = typer.Option(Path("results/graphs/ingested/edges.parquet"), "--edges"),
                  spec: Optional[Path] = typer.Option(None, "--spec", help="complete this partial graph (YAML)"),
                  n: Optional[int] = typer.Option(None, "-n", "--count", help="graphs (default graph_model.sample.graphs)"),
                  out_nodes: Optional[Path] = typer.Option(None, "--out-nodes"),
                  out_edges: Optional[Path] = typer.Option(None, "--out-edges"),
                  out_summary: Optional[Path] = typer.Option(None, "--out-summary"),
                  threads: int = typer.Option(1, "--threads", help="CPU threads")) -> None:
    """Sample relation graphs of a room type, from scratch or completing --spec; writes generated_{nodes,edges}."""
    from .stages import sample_graphs as stage

    if room_type is None:
        if spec is None:
            _fail("give --room-type or --spec")
        room_type = _guard(stage.spec_room_type, spec)
    folder = Path("results/graph_model") / room_type / ("completed" if spec else "sampled")
    model = model or Path("results/graph_model") / room_type / "model.pt"
    _summary(_stage(stage.run, config, config_json, room_type, model, nodes, edges, out_nodes or folder / "nodes.parquet",
                    out_edges or folder / "edges.parquet", out_summary or folder / "summary.json", spec, n, threads),
             skip=("rejections",))


@app.command("graph-model-metrics")
def graph_model_metrics(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                        room_type: str = typer.Option(..., "--room-type"), model: Path = _file("--model"),
                        nodes: Path = _file("--nodes"), edges: Path = _file("--edges"),
                        gen_nodes: Path = _file("--gen-nodes"), gen_edges: Path = _file("--gen-edges"),
                        sample_summary: Path = _file("--sample-summary"), out: Path = _file("--out")) -> None:
    """Evaluate a room type's graph model (held-out NLL; generated vs held-out graphs beside the sampling floor)."""
    from .stages import graph_model_metrics as stage

    result = _stage(stage.run, config, config_json, room_type, model, nodes, edges, gen_nodes, gen_edges,
                    sample_summary, out)
    typer.echo(json.dumps(result["goals"]))


def _workflow_config() -> Optional[Path]:
    """config/config.yaml of the current folder, the config a `snakemake` run here used (None: the defaults)."""
    path = Path("config/config.yaml")
    return path if path.exists() else None


@app.command("train-placement")
def train_placement(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                    room_type: str = typer.Option(..., "--room-type"),
                    net: str = typer.Option("cfcn", "--net", help="cfcn (FiLM-conditioned) or fcn (the unconditional ablation)"),
                    rooms: List[Path] = _files("--rooms"), architecture: List[Path] = _files("--architecture"),
                    objects: List[Path] = _files("--objects"), nodes: Path = _file("--nodes", "final nodes"),
                    edges: Path = _file("--edges", "final edges"), out_model: Path = _file("--out-model"),
                    out_history: Path = _file("--out-history"), out_curve: Path = _file("--out-curve"),
                    out_summary: Path = _file("--out-summary"),
                    threads: int = typer.Option(1, "--threads", help="CPU threads (the rule's threads)")) -> None:
    """Train the location and orientation networks of one room type (resumes from the checkpoint beside --out-model)."""
    from .stages import train_placement as stage

    if net not in ("cfcn", "fcn"):
        _fail(f"--net: '{net}' is not one of cfcn, fcn")
    _summary(_stage(stage.run, config, config_json, room_type, net, rooms, architecture, objects, nodes, edges, out_model,
                    out_history, out_curve, out_summary, threads))


@app.command()
def instantiate(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                room_type: str = typer.Option(..., "--room-type"),
                variant: str = typer.Option("planit", "--variant", help="a key of instantiate.variants"),
                nodes: Path = _file("--nodes", "graphs: generated (sampled) or final nodes"), edges: Path = _file("--edges"),
                model: Path = _file("--model", "placement networks"), rooms: List[Path] = _files("--rooms"),
                architecture: List[Path] = _files("--architecture"), objects: List[Path] = _files("--objects"),
                models: List[Path] = _files("--models"), symmetry: Path = _file("--symmetry"),
                category_sizes: Path = _file("--category-sizes"), out: Path = _file("--out", "output folder"),
                n: Optional[int] = typer.Option(None, "-n", "--count", help="scenes (default from instantiate)"),
                threads: int = typer.Option(1, "--threads", help="CPU threads (the rule's threads)")) -> None:
    """Place graphs of one room type into rooms: canonical tables, a record per scene, GLB / PNG / JSON per scene."""
    from .stages import instantiate as stage

    _summary(_stage(stage.run, config, config_json, room_type, variant, nodes, edges, model, rooms, architecture, objects,
                    models, symmetry, category_sizes, out, n, threads))


@app.command()
def table3(summary: List[Path] = _files("--summary", "one per variant"), out: Path = _file("--out")) -> None:
    """Gather the variants' summaries of one room type into PlanIT's Table 3 (CSV)."""
    from .stages import instantiate as stage

    typer.echo(_guard(stage.table3, summary, out).to_string(index=False))


@app.command()
def evaluate(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
             room_type: str = typer.Option(..., "--room-type"),
             generated: List[str] = typer.Option(..., "--generated", help="NAME=FOLDER, an instantiation output; the first is the default generator"),
             rooms: List[Path] = _files("--rooms"), architecture: List[Path] = _files("--architecture"),
             objects: List[Path] = _files("--objects"), models: List[Path] = _files("--models"),
             nodes: Path = _file("--nodes", "the corpus's final nodes (the held-out split)"),
             edges: Path = _file("--edges", "the corpus's final edges (the gallery's real graphs)"),
             symmetry: Path = _file("--symmetry", "the corpus's symmetry table (extraction)"),
             out_metrics: Path = _file("--out-metrics"), out_scenes: Path = _file("--out-scenes"),
             out_table: Path = _file("--out-table", "the sets side by side (CSV)"),
             out_gallery: Path = _file("--out-gallery", "folder of generated and real rooms (PNG, GLB)"),
             threads: int = typer.Option(1, "--threads", help="CPU threads (the rule's threads)")) -> None:
    """Score generated rooms, baselines and held-out real rooms of one room type with the same metrics."""
    from .stages import evaluate as stage

    pairs = [g.partition("=") for g in generated]
    if any(not sep or not name for name, sep, _ in pairs):
        _fail("--generated takes NAME=FOLDER")
    m = _stage(stage.run, config, config_json, room_type, [(n, Path(f)) for n, _, f in pairs], rooms, architecture,
               objects, models, nodes, edges, symmetry, out_metrics, out_scenes, out_table, out_gallery, threads)
    typer.echo(" ".join(f"{name}: kl={s['category_kl']} collide={s['object_collision_rate']} "
                        f"walk={s['walkable_share']} sca={(s.get('sca') or {}).get('mean')}" for name, s in m["sets"].items()))


@app.command()
def runtime(benchmarks: Path = typer.Option(Path("benchmarks"), "--benchmarks", help="Snakemake's benchmark folder"),
            out: Path = _file("--out", "runtime.csv")) -> None:
    """Job seconds and peak memory per rule from the benchmark files, and the run's wall-clock span (CSV)."""
    from .stages import runtime as stage

    typer.echo(_guard(stage.run, benchmarks, out).to_string(index=False))


@app.command()
def generate(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
             room_type: Optional[str] = typer.Option(None, "--room-type", help="default: the spec's room_type"),
             spec: Optional[Path] = typer.Option(None, "--spec", help="complete this partial graph (YAML) first"),
             n: int = typer.Option(10, "-n", "--count", help="rooms"),
             out: Optional[Path] = typer.Option(None, "--out", help="default results/generated/<type>/cli (or spec_<name>)")) -> None:
    """Sample graphs with the trained graph model (from scratch or completing --spec) and place them, end to end to
    GLB; needs the trained models of `snakemake` (results/graph_model, results/placement). The config defaults to
    the workflow's config/config.yaml."""
    from .stages import generate as stage
    from .stages import sample_graphs

    config = config or _workflow_config()

    if room_type is None:
        if spec is None:
            _fail("give --room-type or --spec")
        room_type = _guard(sample_graphs.spec_room_type, spec)
    folder = out or Path("results/generated") / room_type / (f"spec_{spec.stem}" if spec else "cli")
    _summary(_stage(stage.generate, config, config_json, room_type, spec, n, folder))


@app.command()
def complete(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
             room: str = typer.Option(..., "--room", help="a kept room of the corpus"),
             keep: int = typer.Option(3, "--keep", help="objects kept where they are (the first of the placement order)"),
             out: Optional[Path] = typer.Option(None, "--out", help="default results/generated/<type>/complete_<room>")) -> None:
    """Keep a real room's first objects and place the rest of its graph around them (config: as for generate)."""
    from .stages import generate as stage

    config = config or _workflow_config()

    _summary(_stage(stage.complete, config, config_json, room, keep, out))


@app.command()
def stats(path: Path = typer.Argument(..., help="a pipeline Parquet table, 'graphs' / a folder of gathered graph tables, "
                                               "or 'graph_model' / a metrics JSON"),
          room: Optional[str] = typer.Option(None, "--room", help="print this room's graph")) -> None:
    """Print a table's schema, row count and per-column summary; for graphs, the per-room-type report. Reads only."""
    if str(path) == "graphs" and not path.exists():
        path = Path("results/graphs/ingested")
    if str(path) == "graph_model" and not path.exists():
        path = Path("results/graph_model")
    if path.is_dir() and (path / "metrics.json").exists() or path.suffix == ".json" or path.name == "graph_model":
        from .inspect import print_metrics

        _guard(print_metrics, path, sys.stdout)
        return
    if path.is_dir():
        from .graphs.report import graph_report as report_of, graph_tables, print_report, print_room

        if room:
            _guard(print_room, path, room, sys.stdout)
        else:
            print_report(_guard(report_of, *graph_tables(path)), sys.stdout)
        return
    from .inspect import table_summary

    _guard(table_summary, path, sys.stdout)


if __name__ == "__main__":  # pragma: no cover
    app()
