"""The ``planit`` command line: one subcommand per pipeline stage (the Snakemake rules call these) and ``stats``."""
from __future__ import annotations

import logging
import sys
from pathlib import Path
from typing import Optional

import typer

from . import config as config_mod
from .log import setup

app = typer.Typer(add_completion=False, no_args_is_help=True, help=__doc__)
log = logging.getLogger("planit")

ConfigOpt = typer.Option(None, "--config", "-c", help="YAML config (validated against config/schema.yaml)")
JsonOpt = typer.Option(None, "--config-json", help="JSON object merged over the config (the Snakemake rules pass their sections)")


def _config(path: Optional[Path], overrides: Optional[str]) -> dict:
    try:
        return config_mod.load(path, overrides)
    except config_mod.ConfigError as exc:
        _fail(str(exc))


def _fail(message: str) -> None:
    log.error(message)
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code=2)


def _summary(values: dict, skip: tuple[str, ...] = ()) -> None:
    """One line of key=value pairs: what a stage did."""
    typer.echo(" ".join(f"{k}={v}" for k, v in values.items() if k not in skip))


def _metrics(values: dict) -> None:
    """One 'key: value' line per metric."""
    for key, value in values.items():
        typer.echo(f"{key}: {value}")


def _guard(fn, *args, **kwargs):
    """Run a stage; known input errors become a one-line message and exit code 2."""
    from .tables import TableError
    from .geometry.raycast import BackendError

    try:
        return fn(*args, **kwargs)
    except (TableError, BackendError, config_mod.ConfigError, NotImplementedError, FileNotFoundError, KeyError) as exc:
        _fail(str(exc))


def _stage(fn, config: Optional[Path], overrides: Optional[str], *args):
    """Load and validate the config, then run a stage function on it (guarded)."""
    return _guard(fn, _config(config, overrides), *args)


@app.callback()
def main(verbose: bool = typer.Option(False, "--verbose", "-v")) -> None:
    setup(verbose)


@app.command()
def ingest(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
           out: Path = typer.Option(Path("results/ingest"), help="output folder")) -> None:
    """Read the configured source into canonical tables (rooms, architecture, objects, models, ground_truth)."""
    from .stages import ingest as stage

    counts = _stage(stage.run, config, config_json, out)
    _summary(counts)


@app.command("filter")
def filter_(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
            ingest_dir: Path = typer.Option(Path("results/ingest"), "--ingest"),
            out: Path = typer.Option(Path("results/filter"))) -> None:
    """Filter rooms (every rejection has a reason) and assign kept rooms to shards."""
    from .filtering import rule_counts
    from .stages import filter as stage

    report = _stage(stage.run, config, config_json, ingest_dir, out)
    typer.echo(rule_counts(report).to_string(index=False))


@app.command()
def symmetry(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
             ingest_dir: Path = typer.Option(Path("results/ingest"), "--ingest"),
             out: Path = typer.Option(Path("results/symmetry"))) -> None:
    """Assign a functional symmetry type to every model (config table, else detected from the mesh)."""
    from .stages import symmetry as stage

    summary = _stage(stage.run, config, config_json, ingest_dir, out)
    typer.echo(f"models={summary['models']} agreement={summary['agreement']} ({summary['agree']}/{summary['compared']})")


@app.command()
def extract(shard: int = typer.Option(..., help="shard index"), config: Optional[Path] = ConfigOpt,
            config_json: Optional[str] = JsonOpt,
            ingest_dir: Path = typer.Option(Path("results/ingest"), "--ingest"),
            filter_dir: Path = typer.Option(Path("results/filter"), "--filter"),
            symmetry_path: Path = typer.Option(Path("results/symmetry/symmetry.parquet"), "--symmetry"),
            out: Path = typer.Option(Path("results/graphs/raw"))) -> None:
    """Ray-cast one shard's rooms into raw relation graphs (nodes, edges)."""
    from .stages import extract as stage

    summary = _stage(stage.run, config, config_json, shard, ingest_dir, filter_dir, out, symmetry_path)
    _summary(summary)


@app.command()
def score(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
          ingest_dir: Path = typer.Option(Path("results/ingest"), "--ingest"),
          raw_dir: Path = typer.Option(Path("results/graphs/raw"), "--raw"),
          out: Path = typer.Option(Path("results/metrics/extraction.json"))) -> None:
    """Score extracted graphs against the source's ground truth (support parents, intended adjacencies)."""
    from .stages import score as stage

    metrics = _stage(stage.run, config, config_json, ingest_dir, raw_dir, out)
    _metrics(metrics)


@app.command("graph-stats")
def graph_stats(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                raw_dir: Path = typer.Option(Path("results/graphs/raw"), "--raw"),
                out: Path = typer.Option(Path("results/graphs/stats"))) -> None:
    """Dataset-wide statistics over every shard's raw graphs: co-occurrence, relation frequencies, hub patterns, sizes."""
    from .stages import graphs as stage

    summary = _stage(stage.run_statistics, config, config_json, raw_dir, out)
    _summary(summary)


@app.command()
def refine(shard: int = typer.Option(..., help="shard index"), config: Optional[Path] = ConfigOpt,
           config_json: Optional[str] = JsonOpt,
           raw_dir: Path = typer.Option(Path("results/graphs/raw"), "--raw"),
           stats_dir: Path = typer.Option(Path("results/graphs/stats"), "--stats"),
           out: Path = typer.Option(Path("results/graphs/final"))) -> None:
    """Superstructures, pruning and connectivity repair for one shard's raw graphs."""
    from .stages import graphs as stage

    summary = _stage(stage.run_refine, config, config_json, shard, raw_dir, stats_dir, out)
    _summary(summary, skip=("cyclic_room_ids",))


@app.command("gather-graphs")
def gather_graphs(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                  final_dir: Path = typer.Option(Path("results/graphs/final"), "--final"),
                  out: Path = typer.Option(Path("results/graphs"))) -> None:
    """Concatenate the refined shards into results/graphs/{nodes,edges,superstructures}.parquet."""
    from .stages import graphs as stage

    counts = _stage(stage.run_gather, config, config_json, final_dir, out)
    _summary(counts)


@app.command("score-graphs")
def score_graphs(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
                 ingest_dir: Path = typer.Option(Path("results/ingest"), "--ingest"),
                 graph_dir: Path = typer.Option(Path("results/graphs"), "--graphs"),
                 out: Path = typer.Option(Path("results/metrics/superstructures.json"))) -> None:
    """Hub and chain precision / recall against the source's ground truth."""
    from .stages import score as stage

    metrics = _stage(stage.run_superstructures, config, config_json, ingest_dir, graph_dir, out)
    _metrics(metrics)


@app.command()
def stats(path: Path = typer.Argument(..., help="a pipeline Parquet table, or 'graphs' / a folder of final graph tables"),
          room: Optional[str] = typer.Option(None, "--room", help="print this room's graph"),
          out: Optional[Path] = typer.Option(None, "--out", help="graphs: where to write the CSVs and the PNG")) -> None:
    """Print a table's schema, row count and per-column summary; for graphs, the per-room-type report."""
    if str(path) == "graphs" and not path.exists():
        path = Path("results/graphs")
    if path.is_dir():
        from .graphs.report import graph_report, print_report, print_room, write_report

        if room:
            _guard(print_room, path, room, sys.stdout)
            return
        report = _guard(graph_report, path)
        print_report(report, sys.stdout)
        for p in write_report(report, out or path / "report"):
            typer.echo(f"wrote {p}")
        return
    from .inspect import table_summary

    _guard(table_summary, path, sys.stdout)


if __name__ == "__main__":  # pragma: no cover
    app()
