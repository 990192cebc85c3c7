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


def _guard(fn, *args, **kwargs):
    """Run a stage; known input errors become a one-line message and exit code 2."""
    from .tables import TableError
    from .geometry.raycast import BackendError

    try:
        return fn(*args, **kwargs)
    except (TableError, BackendError, config_mod.ConfigError, NotImplementedError, FileNotFoundError) as exc:
        _fail(str(exc))


@app.callback()
def main(verbose: bool = typer.Option(False, "--verbose", "-v")) -> None:
    setup(verbose)


@app.command()
def ingest(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
           out: Path = typer.Option(Path("results/ingest"), help="output folder")) -> None:
    """Read the configured source into canonical tables (rooms, architecture, objects, models, ground_truth)."""
    from .stages import ingest as stage

    cfg = _config(config, config_json)
    counts = _guard(stage.run, cfg, out)
    typer.echo(" ".join(f"{k}={v}" for k, v in counts.items()))


@app.command("filter")
def filter_(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
            ingest_dir: Path = typer.Option(Path("results/ingest"), "--ingest"),
            out: Path = typer.Option(Path("results/filter"))) -> None:
    """Filter rooms (every rejection has a reason) and assign kept rooms to shards."""
    from .filtering import rule_counts
    from .stages import filter as stage

    cfg = _config(config, config_json)
    report = _guard(stage.run, cfg, ingest_dir, out)
    typer.echo(rule_counts(report).to_string(index=False))


@app.command()
def symmetry(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
             ingest_dir: Path = typer.Option(Path("results/ingest"), "--ingest"),
             out: Path = typer.Option(Path("results/symmetry"))) -> None:
    """Assign a functional symmetry type to every model (config table, else detected from the mesh)."""
    from .stages import symmetry as stage

    cfg = _config(config, config_json)
    summary = _guard(stage.run, cfg, ingest_dir, out)
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

    cfg = _config(config, config_json)
    summary = _guard(stage.run, cfg, shard, ingest_dir, filter_dir, out, symmetry_path)
    typer.echo(" ".join(f"{k}={v}" for k, v in summary.items()))


@app.command()
def score(config: Optional[Path] = ConfigOpt, config_json: Optional[str] = JsonOpt,
          ingest_dir: Path = typer.Option(Path("results/ingest"), "--ingest"),
          raw_dir: Path = typer.Option(Path("results/graphs/raw"), "--raw"),
          out: Path = typer.Option(Path("results/metrics/extraction.json"))) -> None:
    """Score extracted graphs against the source's ground truth (support parents, intended adjacencies)."""
    from .stages import score as stage

    cfg = _config(config, config_json)
    metrics = _guard(stage.run, cfg, ingest_dir, raw_dir, out)
    for key, value in metrics.items():
        typer.echo(f"{key}: {value}")


@app.command()
def stats(path: Path = typer.Argument(..., help="a pipeline Parquet table")) -> None:
    """Print a table's schema, metadata, row count and per-column summary."""
    from .inspect import table_summary

    _guard(table_summary, path, sys.stdout)


if __name__ == "__main__":  # pragma: no cover
    app()
