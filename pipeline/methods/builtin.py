"""The built-in methods: PlanIT and its baselines (instantiate.variants of sampled graphs), and retrieval."""
from __future__ import annotations

from .interface import Method


def search_keys(config: dict, name: str) -> list[str]:
    """The keys PlanIT's search reads for one variant: every instantiate key but the variants (its own variant's
    spec only, so adding another variant reruns nothing), the extraction and the evaluation's penetration measure
    its collision check confirms with."""
    own = [f"instantiate.{k}" for k in config["instantiate"] if k not in ("variants", "table3_room_types")]
    return ["seed", "extract", "floor_contact", *own, f"instantiate.variants.{name}", "evaluate.collision.penetration"]


def search_scenes(config: dict, name: str) -> int:
    ic = config["instantiate"]
    return min(ic["scenes"], ic["variants"][name].get("scenes", ic["scenes"]))


def _search(name: str, net: str, description: str) -> Method:
    return Method(name, "pipeline.methods.planit.layout:PlanitLayout", graphs="planit", model=net, keys=search_keys,
                  scenes=search_scenes, description=description)


BUILTIN = [
    _search("planit", "cfcn", "PlanIT: the graph model's sampled graphs placed by the search with the CFCN"),
    _search("random_sampled", "cfcn", "the sampled graphs' objects at uniform random locations (collision-checked)"),
    _search("unconditional_sampled", "fcn", "the sampled graphs placed with the location network without FiLM"),
    Method("retrieval", "pipeline.methods.retrieval:Retrieval", reference="planit",
           keys=lambda config, name: ["evaluate.render"],
           description="each of PlanIT's rooms replaced by its nearest training room (the memorisation floor)"),
]
