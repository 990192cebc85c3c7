"""The stages, declared once: each one's files and parameters (``pipeline.stage``). A stage module of the same name
reads its files, calls one function of the domain packages and writes its files; the ``planit`` subcommand and the
Snakemake rule of the same name are derived from (and checked against) these declarations. Stage modules do not
import each other."""
from __future__ import annotations

from ..stage import Param, Stage, many, one

SHARD = Param("shard", int, help="shard index")
ROOM_TYPE = Param("room_type", help="room type")
METHOD = Param("method", help="a generation method (generation.methods)")
GENERATOR = Param("generator", default="planit", help="a registered graph generator (planit, strings)")
CORPUS = (one("rooms", "the shard's rooms"), one("architecture"), one("objects"), one("models"))
CORPUS_SHARDS = (many("rooms", "the kept rooms, one per shard"), many("architecture"), many("objects"), many("models"))
GRAPHS = (one("nodes", "final nodes"), one("edges", "final edges"))
SPLIT = one("split", "the room type's split (fit, validation, heldout)")
TRAINING = (one("model", "the trained model"), one("history", "loss per epoch or step (CSV)"),
            one("curve", "loss curves (PNG)"), one("summary", "training summary (JSON)"))
GENERATED = (one("rooms"), one("architecture"), one("objects"), one("models"),
             one("scenes", "one record per scene, failed ones with their reason"), one("summary", "JSON"),
             one("archive", "zip archive of a GLB, PNG and JSON per scene"))

_ALL = [
    Stage("ingest", "Read one shard of the configured source into canonical tables.",
          outputs=(one("rooms"), one("architecture"), one("objects"), one("models"), one("ground_truth"),
                   one("ingest_report", "the shard's ingest report"),
                   one("drops", "one row per dropped house, room, object or model")), params=(SHARD,)),
    Stage("ingest_summary", "Gather the ingest shards: category counts for the filter, the summed ingest report, "
          "every drop.", inputs=(many("rooms"), many("objects"), many("models"), many("reports"), many("drops")),
          outputs=(one("counts"), one("report"), one("drops"))),
    Stage("filter_rooms", "Filter one shard's rooms (every rejection has a reason; interpenetration measured on the "
          "meshes).", inputs=(*CORPUS, one("counts", "category_counts.parquet")), outputs=(one("rooms"), one("report"))),
    Stage("filter_report", "Gather the filter reports; print rooms per room type and outcome.",
          inputs=(many("reports"),), outputs=(one("report"), one("counts", "rule_counts.tsv"),
                   one("counts_html", "the counts as a sortable HTML table (the report's)"))),
    Stage("symmetry", "Assign a functional symmetry type to every model (config table, else detected from the mesh).",
          inputs=(many("models"),), outputs=(one("table"), one("agreement"))),
    Stage("extract_graphs", "Ray-cast one shard's rooms into raw relation graphs (nodes, edges).",
          inputs=(*CORPUS, one("symmetry")), outputs=(one("nodes"), one("edges"), one("summary")), params=(SHARD,)),
    Stage("score_extraction", "Score raw graphs against the corpus's ground truth (support parents, intended "
          "adjacencies).", inputs=(many("nodes"), many("edges"), many("ground_truth")), outputs=(one("metrics"),)),
    Stage("shard_statistics", "One shard's partial counts and superstructure candidates (the map step of the "
          "statistics).", inputs=(one("nodes"), one("edges")), outputs=(one("counts"), one("candidates"))),
    Stage("graph_statistics", "Dataset-wide statistics: the shards' partial counts summed, hub patterns accepted, "
          "category sizes.", inputs=(many("partial"), many("nodes")),
          outputs=(one("cooccurrence"), one("relations"), one("hub_patterns"), one("category_sizes"))),
    Stage("refine_graphs", "Superstructures, pruning and connectivity repair for one shard's raw graphs.",
          inputs=(one("nodes"), one("edges"), one("candidates"), one("relations"), one("hub_patterns"),
                  one("category_sizes")),
          outputs=(one("nodes"), one("edges"), one("superstructures"), one("summary")), params=(SHARD,)),
    Stage("gather_graphs", "Concatenate the refined shards into one nodes, edges and superstructures table.",
          inputs=(many("nodes"), many("edges"), many("superstructures")),
          outputs=(one("nodes"), one("edges"), one("superstructures"))),
    Stage("score_superstructures", "Hub and chain precision / recall against the corpus's ground truth.",
          inputs=(one("nodes"), one("superstructures"), many("ground_truth")), outputs=(one("metrics"),)),
    Stage("graph_report", "Write the graph report: Table 1, pruning by rule, frequent relations (CSV), Table 1 and "
          "pruning as HTML (the report's) and a PNG.",
          inputs=(one("nodes"), one("edges"), one("superstructures")),
          outputs=(one("table1"), one("pruning"), one("relations"), one("plot"),
                   one("table1_html", "Table 1 as a sortable HTML table"),
                   one("pruning_html", "the pruning table as a sortable HTML table"))),
    Stage("room_types", "The room types to learn: the candidates with enough graphs, the others skipped with a reason.",
          inputs=(one("nodes", "final nodes"),),
          outputs=(one("table", "room_types.csv"), one("table_html", "the table as a sortable HTML table"))),
    Stage("split_rooms", "Split one room type's rooms into fit, validation and held-out rooms (seeded).",
          inputs=(one("nodes", "final nodes"),), outputs=(one("split"),), params=(ROOM_TYPE,)),
    Stage("train_graph_model", "Train the graph generative model of one room type (resumes from the checkpoint "
          "beside --out-model).", inputs=(*GRAPHS, SPLIT), outputs=TRAINING, params=(ROOM_TYPE, GENERATOR), threads=True),
    Stage("sample_graphs", "Sample relation graphs of a room type, from scratch or completing --spec.",
          inputs=(one("model", "the graph model"), *GRAPHS, one("spec", "complete this partial graph (YAML)", True)),
          outputs=(one("nodes"), one("edges"), one("summary")),
          params=(ROOM_TYPE, Param("count", int, None, "graphs (default: the generator's sample.graphs)"), GENERATOR),
          threads=True),
    Stage("complete_graphs", "Complete a partial graph (a YAML spec) with its room type's graph model.",
          inputs=(one("model", "the spec's room type's graph model"), *GRAPHS, one("spec_file", "the partial graph (YAML)")),
          outputs=(one("nodes"), one("edges"), one("summary")),
          params=(Param("spec", help="the spec's name"), Param("count", int, None, "graphs (default "
                                                                   "graph_model.sample.spec_graphs)")), threads=True),
    Stage("graph_model_metrics", "Evaluate a room type's graph model (held-out NLL; generated vs held-out graphs "
          "beside the sampling floor).", inputs=(one("model"), *GRAPHS, one("gen_nodes"), one("gen_edges"),
                                                 one("sample_summary")),
          outputs=(one("metrics"),), params=(ROOM_TYPE, GENERATOR)),
    Stage("train_placement", "Train one placement learner of one room type: PlanIT's location and orientation "
          "networks, or the string method's edge tagger (resumes from the checkpoint beside --out-model).",
          inputs=(*CORPUS_SHARDS[:3], *GRAPHS, SPLIT), outputs=TRAINING,
          params=(ROOM_TYPE, Param("net", help="cfcn (FiLM-conditioned), fcn (the unconditional ablation) or tagger (the string "
                                              "method's edge tagger)")),
          threads=True),
    Stage("learn_program", "Learn one room type's readable program from its training rooms: Infinigen's constraint "
          "program (derived from the final graphs' statistics) or S-AOG's grammar (with its weights).",
          inputs=(*CORPUS_SHARDS[:3], *GRAPHS, SPLIT),
          outputs=(one("program", "the program (YAML, readable and editable)"), one("summary", "what it was learned "
                       "from and the statistics behind each choice (JSON)")),
          params=(ROOM_TYPE, Param("program", help="a registered program learner (infinigen, saog)"))),
    Stage("generate", "Generate rooms of one room type with one method: canonical tables, a record per scene, "
          "GLB / PNG / JSON per scene.",
          inputs=(*CORPUS_SHARDS, SPLIT, one("symmetry"), one("category_sizes"),
                  one("nodes", "the method's graphs (its graph generator's sampled nodes)", True),
                  one("edges", optional=True), one("model", "the placement networks the method reads", True),
                  one("program", "the method's constraint program or grammar (YAML; results/programs/<type>/)", True),
                  *(one(f"reference_{t}", "the rooms of the method's reference method", True)
                    for t in ("rooms", "architecture", "objects", "scenes"))),
          outputs=GENERATED, params=(ROOM_TYPE, METHOD, Param("count", int, None, "scenes (default: the method's)")),
          threads=True),
    Stage("instantiate", "Place the held-out rooms' own graphs under one of Table 3's ablations "
          "(instantiate.variants of held-out graphs).",
          inputs=(one("nodes", "final nodes"), one("edges", "final edges"), one("model", "placement networks"),
                  *CORPUS_SHARDS, SPLIT, one("symmetry"), one("category_sizes")),
          outputs=GENERATED, params=(ROOM_TYPE, Param("variant", help="a key of instantiate.variants"),
                                     Param("count", int, None, "scenes (default instantiate.table3_scenes)")),
          threads=True),
    Stage("place_graphs", "Place given graphs (a spec's completions) into their rooms with PlanIT's search.",
          inputs=(one("nodes", "the graphs (generated_nodes)"), one("edges"), one("model", "placement networks"),
                  *CORPUS_SHARDS, SPLIT, one("symmetry"), one("category_sizes")), outputs=GENERATED, threads=True),
    Stage("complete_room", "Keep a real room's first objects where they are and place the rest of its graph.",
          inputs=(one("nodes", "final nodes"), one("edges", "final edges"), one("model", "placement networks"),
                  *CORPUS_SHARDS, SPLIT, one("symmetry"), one("category_sizes")), outputs=GENERATED,
          params=(ROOM_TYPE, Param("room", help="a kept room of the corpus"),
                  Param("keep", int, help="objects kept where they are (the first of the placement order)")),
          threads=True),
    Stage("table3", "Gather the variants' summaries of one room type into PlanIT's Table 3 (CSV and HTML).",
          inputs=(many("summaries", "one per variant"),
                  many("nets", "the training summaries of the networks the variants read (held-out pose log-likelihood)",
                       True)),
          outputs=(one("table"), one("table_html", "the table as a sortable HTML table"))),
    Stage("evaluate", "Score every method's rooms and the held-out real rooms of one room type with the same "
          "metrics.", inputs=(many("summaries", "one per generated set (its name: the summary's method)"),
                              many("generated_rooms"), many("generated_architecture"), many("generated_objects"),
                              many("generated_scenes"), many("generated_archives", "each set's scene archive (gallery)"),
                              *CORPUS_SHARDS, *GRAPHS, SPLIT, one("symmetry")),
          outputs=(one("metrics"), one("scenes"), one("table", "the sets side by side (CSV)"),
                   one("table_html", "every method beside the real rooms with intervals, the functional checks, the "
                       "classifier and its power check, the goals (HTML)"),
                   one("power", "the classifier's power check (PNG)"),
                   one("gallery", "generated and held-out real rooms side by side (PNG)")), params=(ROOM_TYPE,),
          threads=True),
    Stage("gallery_3d", "The gallery's rooms in 3D: each method's first placed scenes (planned graph, the graph "
          "extraction finds, their difference) and held-out real rooms (final graph) in one self-contained viewer page.",
          inputs=(many("generated_scenes", "one per method (its folder holds the method's tables)"),
                  many("generated_rooms"), many("generated_architecture"), many("generated_objects"),
                  many("generated_models"), many("sampled_nodes", "the graph generators' sampled graphs", optional=True),
                  many("sampled_edges", optional=True), *CORPUS_SHARDS, *GRAPHS, SPLIT),
          outputs=(one("page", "the viewer page (HTML, three.js inlined)"),), params=(ROOM_TYPE,)),
    Stage("energy_trace", "The annealing methods' energy traces (the first scene of each method) of one room type.",
          inputs=(many("generated_scenes", "one per annealing method"), many("summaries", "the same methods' summaries")),
          outputs=(one("figure", "energy and hard violations over the steps (PNG)"),), params=(ROOM_TYPE,)),
    Stage("export_rooms", "A method's generated rooms of one room type in one format other tools load (usd, procthor "
          "or front3d; docs/formats.md), as one archive.",
          inputs=(one("rooms"), one("architecture"), one("objects"), one("models")),
          outputs=(one("archive", "zip archive of the exported files and export.json"),),
          params=(ROOM_TYPE, METHOD, Param("format", help="usd | procthor | front3d"))),
    Stage("runtime", "Job seconds and peak memory per rule from the benchmark files, and the run's wall-clock span.",
          inputs=(many("corpus", "the corpus stages' outputs (their jobs are timed; read for their presence)"),
                  many("learned", "the learned room types' outputs (likewise)")),
          outputs=(one("table", "runtime.csv"), one("table_html", "the table as a sortable HTML table")),
          params=(Param("benchmarks", str, "benchmarks", "Snakemake's benchmark folder"),)),
]
STAGES: dict[str, Stage] = {s.module: s for s in _ALL}
