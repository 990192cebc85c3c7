"""What a stage is: its input files, output files and parameters, declared once (``pipeline.stages.STAGES``).

From a declaration come the stage's ``planit`` subcommand (an input ``rooms`` is ``--rooms PATH``, repeated for a
per-shard list; an output ``model`` is ``--out-model PATH``; a parameter ``room_type`` is ``--room-type``) and
the options its Snakemake rule passes (``rules/common.smk: stage_io``, from the rule's named ``input`` and
``output``). Adding an input to a stage therefore touches its declaration and its rule, nothing else. A stage
function is ``run(config, inp, out, **params)``; ``inp`` and ``out`` are :class:`Files` of paths.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

REQUIRED = object()


@dataclass(frozen=True)
class Port:
    """One named file of a stage (or, with ``many``, one per shard / per set: a list)."""
    name: str
    many: bool = False
    optional: bool = False
    help: str = ""


class Param(NamedTuple):
    """A scalar option: a wildcard of the rule (shard, room type, method, ...) or a setting of a hand-run
    (``default``: ``REQUIRED`` for a required option)."""
    name: str
    type: type = str
    default: Any = REQUIRED
    help: str = ""


@dataclass(frozen=True)
class Stage:
    """A stage's declaration. ``module``: its module in ``pipeline.stages`` (the rule's and the subcommand's name)."""
    module: str
    help: str
    inputs: tuple[Port, ...] = ()
    outputs: tuple[Port, ...] = ()
    params: tuple[Param, ...] = field(default_factory=tuple)
    threads: bool = False  # the stage takes the rule's thread count

    @property
    def command(self) -> str:
        return self.module.replace("_", "-")


class Files(dict):
    """Paths by port name, readable as attributes (``inp.rooms``)."""

    def __getattr__(self, name: str):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"no file '{name}' among {sorted(self)}") from None


def one(name: str, help: str = "", optional: bool = False) -> Port:
    return Port(name, False, optional, help)


def many(name: str, help: str = "one per shard", optional: bool = False) -> Port:
    return Port(name, True, optional, help)


def option(port: Port, output: bool) -> str:
    """The CLI option of a port: ``--rooms``, ``--out-model``."""
    return ("--out-" if output else "--") + port.name.replace("_", "-")


def files(ports: tuple[Port, ...], values: dict) -> Files:
    """Paths of the given option values (None for an optional port left out)."""
    out = Files()
    for p in ports:
        v = values.get(p.name)
        out[p.name] = [Path(x) for x in v] if p.many else (Path(v) if v is not None else None)
    return out
