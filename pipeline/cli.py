"""The ``planit`` command line: one subcommand per pipeline stage, named as its module and its Snakemake rule and
built from its declaration (``pipeline.stages.STAGES``), ``stats`` and ``view``.

A stage command takes files: its inputs and outputs are exactly the rule's ``{input}`` and ``{output}``. Domain
errors (a bad table, config, input file or missing backend) end in one line naming the file and field, exit code 2;
anything else is a bug and keeps its traceback.
"""
from __future__ import annotations

import importlib
import inspect
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
from .stage import REQUIRED, Stage, files, option
from .stages import STAGES

app = typer.Typer(add_completion=False, no_args_is_help=True, help=__doc__, pretty_exceptions_enable=False)
log = logging.getLogger("planit")

ConfigOpt = typer.Option(None, "--config", "-c", help="YAML config (validated against the package's schema.yaml)")
JsonOpt = typer.Option(None, "--config-json", help="JSON object merged over the config (the Snakemake rules pass the keys they read)")


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


def _stage(fn, config: Optional[Path], overrides: Optional[str], *args, **kwargs):
    """Load and validate the config, then run a stage function on it (guarded). With ``PLANIT_STRICT_KEYS=1`` (the
    Snakemake rules set it) the stage sees only the keys given in ``--config-json``, so a rule whose params miss a
    key its stage reads fails loudly instead of silently reading the default."""
    def run():
        cfg = config_mod.load(config, overrides)
        if os.environ.get("PLANIT_STRICT_KEYS") == "1" and overrides:
            cfg = config_mod.restrict(cfg, json.loads(overrides))
        return fn(cfg, *args, **kwargs)

    return _guard(run)


@app.callback()
def main(verbose: bool = typer.Option(False, "--verbose", "-v")) -> None:
    setup(verbose)


def _options(stage: Stage) -> list[inspect.Parameter]:
    """The subcommand's options, from the stage's declaration."""
    kw = inspect.Parameter.KEYWORD_ONLY
    out = [inspect.Parameter("config", kw, default=ConfigOpt, annotation=Optional[Path]),
           inspect.Parameter("config_json", kw, default=JsonOpt, annotation=Optional[str]),
           inspect.Parameter("threads", kw, default=typer.Option(1, "--threads", help="CPU threads (the rule's threads)"),
                             annotation=int)]
    for output, ports in ((False, stage.inputs), (True, stage.outputs)):
        for p in ports:
            default = None if p.optional else ...
            kind = List[Path] if p.many else (Optional[Path] if p.optional else Path)
            out.append(inspect.Parameter(("out_" if output else "in_") + p.name, kw, annotation=kind,
                                         default=typer.Option(default, option(p, output), help=p.help)))
    for p in stage.params:
        default = ... if p.default is REQUIRED else p.default
        kind = p.type if p.default is not None else Optional[p.type]
        out.append(inspect.Parameter("param_" + p.name, kw, annotation=kind,
                                     default=typer.Option(default, "--" + p.name.replace("_", "-"), help=p.help)))
    return out


def _stage_command(stage: Stage):
    """A subcommand that reads the config, gathers the declared files and calls ``pipeline.stages.<module>.run``."""
    def command(**values) -> None:
        module = importlib.import_module(f"pipeline.stages.{stage.module}")
        inp = files(stage.inputs, {p.name: values["in_" + p.name] for p in stage.inputs})
        out = files(stage.outputs, {p.name: values["out_" + p.name] for p in stage.outputs})
        params = {p.name: values["param_" + p.name] for p in stage.params}
        if stage.threads:
            params["threads"] = values["threads"]
        _print(_stage(module.run, values["config"], values["config_json"], inp, out, **params))
        _wrote([values["out_" + p.name] for p in stage.outputs])

    command.__signature__ = inspect.Signature(_options(stage))
    command.__doc__ = stage.help
    return command


def _wrote(paths: list) -> None:
    """Where a stage wrote: each output file it left (one line)."""
    flat = [Path(p) for x in paths for p in (x if isinstance(x, (list, tuple)) else [x]) if p is not None]
    done = [str(p) for p in flat if p.exists()]
    if done:
        typer.echo("wrote " + " ".join(done))


def _print(result) -> None:
    """What a stage did: a table as text, a dict as one line of key=value pairs (lists by their length)."""
    if result is None:
        return
    if hasattr(result, "to_string"):
        typer.echo(result.to_string(index=False))
        return
    short = lambda v: len(v) if isinstance(v, (list, tuple, set)) else (json.dumps(v) if isinstance(v, dict) else v)
    typer.echo(" ".join(f"{k}={short(v)}" for k, v in result.items()))


for _declared in STAGES.values():
    app.command(_declared.module)(_stage_command(_declared))


@app.command()
def stats(path: Path = typer.Argument(..., help="a pipeline Parquet table, a folder of gathered graph tables "
                                               "(results/graphs/<corpus>), or the graph models' folder "
                                               "(results/graph_model) or one of their metrics JSON"),
          room: Optional[str] = typer.Option(None, "--room", help="print this room's graph")) -> None:
    """Print a table's schema, row count and per-column summary; for graphs, the per-room-type report. Reads only."""
    if not path.exists():
        _fail(f"{path}: no such table, folder or metrics file")
    if path.is_dir() and ((path / "metrics.json").exists() or "graph_model" in path.parts) or path.suffix == ".json":
        from .stats import print_metrics

        _guard(print_metrics, path, sys.stdout)
        return
    if path.is_dir():
        from .graphs.report import graph_report as report_of, graph_tables, print_report, print_room

        if room:
            _guard(print_room, path, room, sys.stdout)
        else:
            print_report(_guard(report_of, *graph_tables(path)), sys.stdout)
        return
    from .stats import table_summary

    _guard(table_summary, path, sys.stdout)


def _planned_graph(folder: Path) -> tuple[Path, Path] | None:
    """The sampled graph tables a generated method's folder (results/generated/<type>/<method>) was planned from."""
    from . import methods

    name, room_type, results = folder.name, folder.parent.name, folder.parents[2] if len(folder.parents) > 2 else Path(".")
    if name not in methods.names() or methods.get(name).graphs is None:
        return None
    base = results / "graph_model" / room_type / methods.get(name).graphs / "sampled"
    return (base / "nodes.parquet", base / "edges.parquet") if (base / "edges.parquet").exists() else None


def _view_payload(path: Optional[Path], room: Optional[str], scene: str, results: Path, config: Optional[Path]) -> dict:
    from .viewer import sources

    if (path is None) == (room is None):
        _fail("planit view: give a generated method's folder (results/generated/<type>/<method>) or --room ID")
    if room is not None:
        return sources.ingested_room(results, room)
    if not path.is_dir():
        _fail(f"{path}: no such folder (a generated method's folder: results/generated/<type>/<method>)")
    cfg = config_mod.load(config) if config else config_mod.validate({})
    return sources.generated_room(path, scene, _planned_graph(path), {**cfg["extract"], "floor_contact": cfg["floor_contact"]})


@app.command()
def view(path: Optional[Path] = typer.Argument(None, help="a generated method's folder: results/generated/<type>/<method>"),
         room: Optional[str] = typer.Option(None, "--room", help="an ingested room's id (with its final graph)"),
         scene: str = typer.Option("0", "--scene", help="a generated scene: its id, or its index among the placed ones"),
         results: Path = typer.Option(Path("results"), "--results", help="the run's results folder (for --room)"),
         out: Optional[Path] = typer.Option(None, "--out", help="the page to write (default results/view/<room>.html)"),
         serve: bool = typer.Option(False, "--serve", help="serve the page over HTTP until Ctrl-C"),
         host: str = typer.Option("127.0.0.1", "--host", help="where --serve listens (0.0.0.0: every interface)"),
         port: int = typer.Option(8000, "--port", help="--serve's port (0: any free one)"),
         config: Optional[Path] = ConfigOpt) -> None:
    """Write a room and its relation graph as a 3D page (three.js, self-contained: opens from file://) and print its
    path; with --serve, also serve it on 127.0.0.1."""
    from .tables import write_atomic
    from .viewer.page import page

    data = _guard(_view_payload, path, room, scene, results, config)
    target = out or results / "view" / f"{data['room_id']}.html"
    html = _guard(page, [data], data["title"])
    target.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(target, lambda tmp: Path(tmp).write_text(html))
    typer.echo(f"wrote {target} ({len(data['objects'])} objects, "
               f"{sum(len(g) for g in data['graphs'].values())} edges over {len(data['graphs'])} graph(s))")
    if serve:
        from .viewer.serve import serve as serve_page

        serve_page(target, host, port, typer.echo)


@app.command("export")
def export(fmt: str = typer.Argument(..., metavar="FORMAT", help="usd | procthor | front3d"),
           path: Path = typer.Argument(..., metavar="PATH", help="a generated set (results/generated/<type>/<method>) or a corpus's "
                                                 "shards (results/ingest/shards)"),
           out: Optional[Path] = typer.Option(None, "--out", help="the folder to write (default PATH/export/FORMAT)"),
           config: Optional[Path] = ConfigOpt) -> None:
    """Write every room of a generated set or a corpus in FORMAT (docs/formats.md) and print where."""
    from .export import export_folder

    cfg = _guard(config_mod.load, config) if config else config_mod.validate({})
    folder, summary = _guard(export_folder, fmt, path, out, {**cfg["export"], "ithor": cfg["ithor"]})
    missing, skipped = summary.get("unmapped") or {}, summary["skipped"]
    typer.echo(f"wrote {summary['rooms']} rooms ({summary['objects']} objects) as {fmt} to {folder}" + (
        f"; left out {sum(missing.values())} objects with no AI2-THOR asset: {', '.join(missing)}" if missing else "") + (
        f"; skipped {len(skipped)} rooms whose walls form no closed loop (export.json names them)" if skipped else ""))


if __name__ == "__main__":  # pragma: no cover
    app()
