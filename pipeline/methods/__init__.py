"""The generation methods, registered in one place: :data:`BUILTIN` below, and any module a config names in
``generation.plugins`` (it calls :func:`register` when imported). See ``interface.py`` for the contract and
``docs/adding-a-method.md`` for a walk through a toy method."""
from __future__ import annotations

import importlib
from types import SimpleNamespace

from ..errors import InputError
from .interface import (
    Corpus,
    Generated,
    GraphGenerator,
    GraphSource,
    LayoutGenerator,
    Method,
    PlacementLearner,
    ProgramLearner,
    Scene,
    Task,
)

__all__ = ["Corpus", "Generated", "GraphGenerator", "GraphSource", "LayoutGenerator", "Method", "Scene", "Task", "register",
           "get", "names", "load_plugins", "layout_of", "graph_generator", "graph_source", "graph_sources_of", "PlacementLearner",
           "placement_learner", "placement_fit",
           "placement_nets_of", "ProgramLearner", "program_learner", "program_fit"]

_METHODS: dict[str, Method] = {}


def register(method: Method) -> Method:
    """Add a method (a name registered twice is an error unless it is the same method)."""
    known = _METHODS.get(method.name)
    if known is not None and known != method:
        raise InputError(f"generation method '{method.name}' is registered twice")
    _METHODS[method.name] = method
    return method


def load_plugins(modules: list[str]) -> None:
    """Import each module of ``generation.plugins`` (they register their methods)."""
    for name in modules:
        try:
            importlib.import_module(name)
        except ImportError as exc:
            raise InputError(f"generation.plugins: cannot import '{name}' ({exc})") from None


def get(name: str) -> Method:
    if name not in _METHODS:
        raise InputError(f"generation method '{name}' is not registered (known: {', '.join(sorted(_METHODS))}; "
                         "generation.plugins names modules that register more)")
    return _METHODS[name]


def names() -> list[str]:
    return sorted(_METHODS)


def _load(path: str):
    module, _, attr = path.partition(":")
    return getattr(importlib.import_module(module), attr)


def layout_of(method: Method, config: dict) -> LayoutGenerator:
    """The method's layout generator, built for ``config``."""
    return _load(method.layout)(config, method.name)


def _registered(table: dict, name: str, what: str):
    """``table[name]``, or an error naming the known entries of the registry of ``what``."""
    if name not in table:
        raise InputError(f"no {what} '{name}' (known: {', '.join(sorted(table))})")
    return table[name]


def graph_source(name: str) -> GraphSource:
    return _registered(GRAPH_SOURCES, name, "graph generator")


def graph_generator(name: str) -> GraphGenerator:
    """The graph generator registered as ``name``: its ``fit`` and ``sample`` functions, imported."""
    src = graph_source(name)
    return SimpleNamespace(fit=_load(src.fit), sample=_load(src.sample))


def graph_sources_of(method_names: list[str]) -> list[str]:
    """The graph generators the named methods place graphs of, in their order."""
    return list(dict.fromkeys(get(m).graphs for m in method_names if get(m).graphs is not None))


def placement_learner(name: str) -> PlacementLearner:
    return _registered(PLACEMENT_LEARNERS, name, "placement learner")


def placement_fit(name: str):
    """The ``fit`` function of the placement learner ``name``, imported."""
    return _load(placement_learner(name).fit)


def placement_nets_of(method_names: list[str]) -> list[str]:
    """The placement learners the named methods read, in their order."""
    return list(dict.fromkeys(get(m).model for m in method_names if get(m).model is not None))


def program_learner(name: str) -> ProgramLearner:
    return _registered(PROGRAM_LEARNERS, name, "program learner")


def program_fit(name: str):
    """The program learner's ``fit`` function, imported."""
    return _load(program_learner(name).fit)


from .builtin import BUILTIN, GRAPH_SOURCES, PLACEMENT_LEARNERS, PROGRAM_LEARNERS  # noqa: E402

for _m in BUILTIN:
    register(_m)
