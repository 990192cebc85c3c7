"""The generation interface: every generator of this project is a *method*, a named pair of a graph generator (or
none) and a layout generator, registered in one place (``pipeline.methods``).

- A **graph generator** learns the relation graphs of a room type from the fit split's final graphs and samples
  graphs for rooms' architectures, or completes a partial graph (:class:`GraphGenerator`). PlanIT's graph model is
  one: its rules ``train_graph_model`` and ``sample_graphs`` write its model and sampled graphs.
- A **layout generator** places objects into rooms' architectures, from the graph generator's graphs or without
  any (:class:`LayoutGenerator`): given a :class:`Task`, it yields one :class:`Scene` per room it generates. It
  trains in rules of its own if it learns anything (PlanIT's placement networks: ``train_placement``).

The ``generate`` rule runs one method for one room type (the ``method`` wildcard): it reads the corpus and the
method's inputs, calls the layout generator, and writes its scenes as canonical tables (``methods/scenes.py``), so
the evaluation and the report read every method's rooms the same way.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterator, Protocol

import pandas as pd

from ..geometry.meshes import Mesh
from ..room import RoomInput, Walls

if TYPE_CHECKING:
    from ..graphs.data import Graph, Vocab
    from ..learning.fitted import Fitted


@dataclass
class Corpus:
    """What every method may read of one room type: the kept rooms (canonical rows and arrays), their split, the
    model shards (meshes) and the symmetry and category-size tables of the corpus."""
    room_type: str
    rooms: pd.DataFrame
    architecture: pd.DataFrame
    objects: pd.DataFrame
    inputs: dict[str, RoomInput]  # room id -> RoomInput with its real objects
    split: dict[str, str]  # room id -> fit | validation | heldout
    models: list[Path]
    symmetry: Path
    category_sizes: Path
    meshes: dict[str, Mesh] = field(default_factory=dict)  # model id -> (vertices, faces) of the room type's objects
    box_models: set[str] = field(default_factory=set)  # models measured as their box

    def ids(self, *parts: str) -> list[str]:
        """Sorted ids of the kept rooms in the named parts of the split."""
        return sorted(r for r, s in self.split.items() if s in parts and r in self.inputs)

    def training(self) -> list[RoomInput]:
        return [self.inputs[r] for r in self.ids("fit", "validation")]

    def heldout(self) -> list[RoomInput]:
        return [self.inputs[r] for r in self.ids("heldout")]


@dataclass
class Generated:
    """Another method's generated rooms (a reference for methods that build on one, e.g. retrieval)."""
    rooms: pd.DataFrame
    architecture: pd.DataFrame
    objects: pd.DataFrame
    scenes: pd.DataFrame


@dataclass
class Task:
    """One method's job for one room type: ``count`` scenes (None: the method's default)."""
    config: dict[str, Any]
    method: str
    corpus: Corpus
    graphs: tuple[Path, Path] | None = None  # (nodes, edges) of the method's graph generator
    model: Path | None = None  # the trained networks the layout reads
    reference: Generated | None = None
    count: int | None = None
    threads: int = 1  # CPU threads for the method's networks (the rule's threads)
    program: Path | None = None  # the method's program: a constraint program or a grammar (YAML), see ProgramLearner


@dataclass
class Scene:
    """One generated room. ``room`` holds the placed objects (its room id is the scene id); ``record``: the
    method's figures for the scenes table (search counts, consistency, ...); ``edges``: the planned graph drawn in
    the scene's PNG; ``parents``: object id -> support parent id. A method that decodes its own architecture
    (GRAINS's faithful mode) sets ``own_architecture`` and no source room: the scene's walls are ``room``'s."""
    scene_id: str
    source_room_id: str | None
    room: RoomInput
    walls: Walls
    status: str = "placed"
    reason: str | None = None
    record: dict[str, Any] = field(default_factory=dict)
    edges: list[Any] = field(default_factory=list)
    parents: dict[str, str | None] = field(default_factory=dict)
    own_architecture: bool = False


class LayoutGenerator(Protocol):
    info: dict[str, Any]  # what the method's summary.json records besides its figures (e.g. PlanIT's variant settings)

    def generate(self, task: Task) -> Iterator[Scene]:
        """Yield the task's scenes, each in one of the corpus's room architectures."""


@dataclass(frozen=True)
class GraphRequest:
    """What a graph generator is asked to sample: ``count`` graphs (None: its config's number) with its ``model``
    file, in the held-out architectures among ``graphs`` (the room type's final graphs, read from the ``nodes`` and
    ``edges`` tables, whose architecture rows the sampled graphs copy), or completing the partial graph ``spec``;
    scene ids ``<prefix>_<k>`` (None: the generator's own prefix)."""
    model: Path
    graphs: list[Graph]
    nodes: Path
    edges: Path
    room_type: str
    spec: Path | None = None
    count: int | None = None
    prefix: str | None = None


@dataclass(frozen=True)
class RoomTypeRows:
    """What a placement learner reads of one room type: its final graph rows (``nodes`` and ``edges`` frames), its
    graphed rooms (``rooms``: room id -> RoomInput) and its ``split`` (room id -> fit | validation | heldout)."""
    nodes: pd.DataFrame
    edges: pd.DataFrame
    rooms: dict[str, RoomInput]
    split: dict[str, str]


class GraphGenerator(Protocol):
    def fit(self, config: dict[str, Any], vocab: Vocab, graphs: list[Graph], split: dict[str, str], room_type: str,
            progress_file: Path, threads: int = 1) -> Fitted:
        """Learn from the fit graphs (validation graphs choose when to stop); return a ``learning.fitted.Fitted``
        (typed checkpoint, history, summary, loss curves). ``progress_file`` resumes an interrupted run."""

    def sample(self, config: dict[str, Any], request: GraphRequest,
               threads: int = 1) -> tuple[list[dict[str, Any]], list[dict[str, Any]], dict[str, Any]]:
        """Graphs in held-out rooms' architectures (or completing the partial graph ``spec``) as generated_nodes /
        generated_edges rows, and a summary of the sampling."""


@dataclass(frozen=True)
class GraphSource:
    """A registered graph generator: ``fit`` and ``sample`` (``"module:function"``, imported when it runs) are the
    two functions of :class:`GraphGenerator`; ``kind`` is its checkpoint's kind, ``section`` its config section;
    ``train_keys(config)`` and ``sample_keys(config)``
    the dotted config keys its ``train_graph_model`` and ``sample_graphs`` jobs read (changing one reruns exactly
    those jobs of this generator)."""
    name: str
    fit: str
    sample: str
    kind: str
    section: str
    train_keys: Callable[[dict[str, Any]], list[str]]
    sample_keys: Callable[[dict[str, Any]], list[str]]


@dataclass(frozen=True)
class PlacementLearner:
    """A registered learner of placement (rule ``train_placement``, its ``net`` wildcard): ``fit``
    (``"module:function"``) is ``fit(config, room_type, net, data, progress_file, threads)`` over one room type's
    :class:`RoomTypeRows` ``data``, returning a ``learning.fitted.Fitted``;
    ``train_keys(config)``: the dotted config keys it reads."""
    name: str
    fit: str
    train_keys: Callable[[dict[str, Any]], list[str]]


@dataclass(frozen=True)
class ProgramLearner:
    """A registered learner of a readable program (rule ``learn_program``, its ``program`` wildcard): Infinigen's
    constraint program or S-AOG's grammar, written as YAML a user can read, edit and pass back (``planit generate
    --program FILE``). ``fit`` (``"module:function"``) is ``fit(config, room_type, node_df, edge_df, inputs, split)``
    over one room type's final graph rows and rooms, returning the program's text and a summary (dict);
    ``train_keys(config)``: the dotted config keys it reads."""
    name: str
    fit: str
    train_keys: Callable[[dict[str, Any]], list[str]]


@dataclass(frozen=True)
class Method:
    """A named generator: a layout generator (``layout``: ``"module:factory"``, imported when the method runs;
    ``factory(config, name)`` returns the :class:`LayoutGenerator`) and the inputs its rule gives it."""
    name: str
    layout: str
    graphs: str | None = None  # the graph generator whose sampled graphs it places ("planit", "strings"), or None
    model: str | None = None  # the placement learner whose checkpoint it reads ("cfcn" | "fcn" | "tagger"), or None
    reference: str | None = None  # the method whose rooms it reads, or None
    program: str | None = None  # the program learner whose YAML it reads ("infinigen" | "saog"), or None
    keys: Callable[[dict[str, Any], str], list[str]] = lambda config, name: ["seed"]  # the config keys it reads
    scenes: Callable[[dict[str, Any], str], int] | None = None  # scenes it generates by default (None: one per held-out room)
    description: str = ""
