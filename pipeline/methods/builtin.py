"""The built-in graph generators (PlanIT's graph model, the string VAE) and methods: PlanIT and its baselines
(instantiate.variants of sampled graphs), the string VAE's graphs placed by PlanIT's search, and retrieval."""
from __future__ import annotations

from .interface import GraphSource, Method, PlacementLearner, ProgramLearner


def _preset_keys(section: str, *more: str):
    """A learner's training keys: its preset's name and sizes, its device and ``more``."""
    return lambda config: ["seed", f"{section}.preset", f"{section}.presets.{config[section]['preset']}",
                           f"{section}.device", *(f"{section}.{k}" for k in more)]


GRAPH_SOURCES = {s.name: s for s in [
    GraphSource("planit", "pipeline.methods.planit.graph_model.fit:fit_room_type",
                "pipeline.methods.planit.graph_model.sample:sample_room_type", "graph_model", "graph_model",
                _preset_keys("graph_model", "max_edges", "heldout_fraction", "validation_fraction"),
                lambda config: ["seed", "graph_model.sample"]),
    GraphSource("strings", "pipeline.methods.strings.fit:fit_room_type", "pipeline.methods.strings.rooms:sample_room_type",
                "strings_vae", "strings",
                _preset_keys("strings"), lambda config: ["seed", "strings.sample", "graph_model.sample.contents"]),
]}


PLACEMENT_LEARNERS = {p.name: p for p in [
    *(PlacementLearner(net, "pipeline.methods.planit.nets.fit:fit_from_tables",
                       _preset_keys("placement", "snap_angle", "none_share")) for net in ("cfcn", "fcn")),
    PlacementLearner("prior", "pipeline.methods.planit.prior_fit:fit_prior", lambda config: ["seed", "placement.prior"]),
    PlacementLearner("grains", "pipeline.methods.grains.fit:fit_grains", _preset_keys("grains", "wall_gap")),
    PlacementLearner("tagger", "pipeline.methods.strings.tagfit:fit_tagger",
                     lambda config: ["seed", "strings.tagger.preset",
                                     f"strings.tagger.presets.{config['strings']['tagger']['preset']}",
                                     "strings.tagger.device", "strings.tagger.bandwidth"]),
]}


PROGRAM_LEARNERS = {p.name: p for p in [
    ProgramLearner("infinigen", "pipeline.methods.infinigen.derive:fit_program",
                   lambda config: ["seed", "infinigen.derive"]),
    ProgramLearner("saog", "pipeline.methods.saog.learn:fit_grammar",
                   lambda config: ["seed", "saog", "instantiate.checks", "floor_contact"]),
]}


# what methods/placing.py's load_context reads (the model pool, the checker, learned support shares):
# a PlanIT search setting (instantiate.samples, ...) reruns none of the methods that only share this context
CONTEXT_KEYS = ("extract", "floor_contact", "instantiate.checks",
                "evaluate.collision.penetration")


def _solver_keys(section: str):
    """The keys an annealing method reads: its section, the placement checks' thresholds it takes as hard limits,
    the context it shares with PlanIT's search (model pool, learned support shares) and the walkability measure."""
    return lambda config, name: ["seed", section, *CONTEXT_KEYS, "evaluate.walk"]


def search_keys(config: dict, name: str) -> list[str]:
    """The keys PlanIT's search reads for one variant: every instantiate key but the variants (its own variant's
    spec only, so adding another variant reruns nothing), the extraction, the evaluation's penetration measure its
    collision check confirms with and the walkability measure a floor object may not lower too far."""
    own = [f"instantiate.{k}" for k in config["instantiate"] if k not in ("variants", "table3_room_types")]
    return ["seed", "extract", "floor_contact", *own, f"instantiate.variants.{name}", "evaluate.collision.penetration",
            "evaluate.walk"]


def search_scenes(config: dict, name: str) -> int:
    ic = config["instantiate"]
    return min(ic["scenes"], ic["variants"][name].get("scenes", ic["scenes"]))


def _search(name: str, net: str, description: str, graphs: str = "planit") -> Method:
    return Method(name, "pipeline.methods.planit.layout:PlanitLayout", graphs=graphs, model=net, keys=search_keys,
                  scenes=search_scenes, description=description)


BUILTIN = [
    _search("planit", "cfcn", "PlanIT: the graph model's sampled graphs placed by the search with the pose networks "
            "(the CFCN and the orientation network, conditioned on every planned edge to what is placed)"),
    _search("planit_prior", "prior", "the same graphs placed by the same search with a relative-pose prior learned "
            "from the fit rooms (no network)"),
    _search("random_sampled", "cfcn", "the sampled graphs' objects at uniform random locations (collision-checked)"),
    _search("unconditional_sampled", "fcn", "the sampled graphs placed with the location network without FiLM"),
    _search("strings", "cfcn", "the string VAE's sampled graphs (Kalojanov et al.) placed by PlanIT's search with the "
            "CFCN", graphs="strings"),
    Method("strings_tagged", "pipeline.methods.strings.tagged:TaggedLayout", graphs="strings", model="tagger",
           keys=lambda config, name: ["seed", "extract", "floor_contact", "instantiate", "evaluate.collision.penetration",
                                      "strings.tagger.placement", "strings.tagger.preset"],
           description="the string VAE's sampled graphs placed the paper's way: each edge tagged with a relative-pose "
           "cluster by the edge tagger, assembled breadth-first from the walls with repair"),
    Method("grains", "pipeline.methods.grains.layout:GrainsLayout", model="grains",
           keys=lambda config, name: ["seed", "grains.scenes", "grains.max_depth", "grains.snap", "grains.retrieval",
                                      "grains.resolve", *CONTEXT_KEYS],
           scenes=lambda config, name: config["grains"]["scenes"],
           description="GRAINS: hierarchies decoded from a recursive VAE's prior, each wall group laid onto a held-out "
           "room's wall, models retrieved by size, colliding floor objects moved apart and off the doors' zones (grains.resolve)"),
    Method("grains_decoded", "pipeline.methods.grains.layout:GrainsDecoded", model="grains",
           keys=lambda config, name: ["seed", "grains.scenes", "grains.max_depth", "grains.snap", *CONTEXT_KEYS],
           scenes=lambda config, name: config["grains"]["scenes"],
           description="GRAINS's faithful mode: the same hierarchies, each furnishing the rectangle its own root and "
           "walls decode (no doors or windows), models retrieved by size, nothing repaired"),
    Method("infinigen", "pipeline.methods.infinigen.layout:InfinigenLayout", program="infinigen",
           keys=_solver_keys("infinigen"), scenes=lambda config, name: config["infinigen"]["scenes"],
           description="an Infinigen-Indoors-style constraint program per room type, derived from the training split, "
           "solved by staged simulated annealing (large, medium, small objects)"),
    Method("saog", "pipeline.methods.saog.layout:SaogLayout", program="saog",
           keys=_solver_keys("saog"), scenes=lambda config, name: config["saog"]["scenes"],
           description="Qi et al.'s S-AOG: a stochastic grammar learned from the training split (counts, sizes, wall "
           "distance and angle, groups, affordances; weights by contrastive divergence), sampled by MCMC over poses"),
    Method("retrieval", "pipeline.methods.retrieval:Retrieval", reference="planit",
           keys=lambda config, name: ["evaluate.render"],
           description="each of PlanIT's rooms replaced by its nearest training room (the memorisation floor)"),
]
