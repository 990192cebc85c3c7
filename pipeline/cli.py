"""The ``planit`` command line: one subcommand per pipeline stage, named as its module and its Snakemake rule and
built from its declaration (``pipeline.stages.STAGES``), and ``stats``.

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

    command.__signature__ = inspect.Signature(_options(stage))
    command.__doc__ = stage.help
    return command


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


if __name__ == "__main__":  # pragma: no cover
    app()
