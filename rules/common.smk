# Config validation, every output path (defined here once) and the helpers every rule file uses (no lambdas in rules).
import json
import shlex
import sys
from pathlib import Path

from snakemake.exceptions import WorkflowError
from snakemake.io import is_flagged

try:
    from pipeline import config as planit_config
except ImportError as exc:
    raise WorkflowError(f"the planit package is not installed for the Python running Snakemake ({sys.executable}): "
                        "run `make setup` and use .venv/bin/snakemake") from exc

try:  # the CLI's validator: same defaults, and a bad key is named in one line
    planit_config.validate(config, "config")
except planit_config.ConfigError as exc:
    raise WorkflowError(str(exc)) from None

from pipeline import methods as planit_methods
from pipeline.graphs.files import spec_room_type
from pipeline.methods.builtin import search_keys
from pipeline.stage import option
from pipeline.stages import STAGES
from pipeline.workflow import prepare_jobs

prepare_jobs(workflow.basedir)  # jobs find the `planit` beside this Python; each sees only its rule's keys

SHARDS = list(range(config["shards"]))
try:  # the methods config lists: built in, or registered by generation.plugins
    planit_methods.load_plugins(config["generation"]["plugins"])
    for _name in config["generation"]["methods"]:
        planit_methods.get(_name)
except Exception as exc:
    raise WorkflowError(f"generation.methods: {exc}") from None
_clash = set(config["generation"]["methods"]) & {v for v, s in config["instantiate"]["variants"].items() if s["graphs"] == "heldout"}
if _clash:
    raise WorkflowError(f"generation.methods: {sorted(_clash)} also name Table 3 variants of instantiate.variants")
ENV = "../environment.yml"


wildcard_constraints:
    corpus="[a-z][a-z0-9_]*",
    shard="[0-9]+",
    room_type="[a-z][a-z0-9_]*",
    spec="[A-Za-z0-9_]+",
    room="[A-Za-z0-9_.]+",
    keep="[0-9]+",
    net="|".join(planit_methods.PLACEMENT_LEARNERS),
    program="|".join(planit_methods.PROGRAM_LEARNERS),
    method="|".join(config["generation"]["methods"]),
    generator="|".join(planit_methods.GRAPH_SOURCES),
    variant="|".join(v for v, s in config["instantiate"]["variants"].items() if s["graphs"] == "heldout"),


# ------------------------------------------------------------------------------------------- paths
INGEST = "results/ingest/shards/{table}-{shard}.parquet"
INGEST_TABLES = ["rooms", "architecture", "objects", "models", "ground_truth", "ingest_report", "drops"]
CATEGORY_COUNTS = "results/ingest/category_counts.parquet"
INGEST_REPORT = "results/ingest/ingest_report.parquet"
DROPS = "results/ingest/drops.parquet"
FILTER_ROOMS = "results/filter/shards/rooms-{shard}.parquet"
FILTER_SHARD_REPORT = "results/filter/shards/report-{shard}.parquet"
FILTER_REPORT = "results/filter/report.parquet"
RULE_COUNTS = "results/filter/rule_counts.tsv"
RULE_COUNTS_HTML = "results/filter/rule_counts.html"  # the report's tables are HTML; their CSV is for programs
SYMMETRY = "results/graphs/{corpus}/symmetry.parquet"
SYMMETRY_AGREEMENT = "results/graphs/{corpus}/symmetry_agreement.json"
RAW = "results/graphs/{corpus}/raw/{table}-{shard}.parquet"
RAW_SUMMARY = "results/graphs/{corpus}/raw/summary-{shard}.json"
PARTIAL = "results/graphs/{corpus}/stats/partial-{shard}.parquet"
CANDIDATES = "results/graphs/{corpus}/stats/candidates-{shard}.parquet"
STATS = "results/graphs/{corpus}/stats/{name}.parquet"
STAT_TABLES = ["cooccurrence", "relations", "hub_patterns", "category_sizes"]
FINAL = "results/graphs/{corpus}/final/{table}-{shard}.parquet"
FINAL_SUMMARY = "results/graphs/{corpus}/final/summary-{shard}.json"
GATHERED = "results/graphs/{corpus}/{table}.parquet"
REPORT = "results/graphs/{corpus}/report/{name}"
METRICS = "results/metrics/{corpus}/{name}.json"
GRAPH_MODEL = "results/graph_model/{room_type}/{generator}/{name}"  # a graph generator's model and graphs
PLACEMENT = "results/placement/{room_type}/{net}/{name}"
PROGRAM = "results/programs/{room_type}/{program}.{name}"  # a readable program (yaml) and its summary (json)
GENERATED = "results/generated/{room_type}/{method}/{name}"
ABLATION = "results/generated/{room_type}/{variant}/{name}"  # Table 3's variants (held-out graphs)
SPEC = "results/specs/{spec}/{name}"  # a partial graph's completions (graphs/) and their rooms
SPEC_FILE = f"{workflow.basedir}/config/specs/{{spec}}.yaml"
COMPLETE = "results/complete/{room_type}/{room}-keep{keep}/{name}"  # a real room completed around its first objects
TABLE3 = "results/generated/{room_type}/table3.csv"
TABLE3_HTML = "results/generated/{room_type}/table3.html"
EVAL = "results/eval/{room_type}/{name}"
SPLIT = "results/splits/{room_type}.parquet"
ROOM_TYPES = "results/graphs/ingested/room_types.csv"
ROOM_TYPES_HTML = "results/graphs/ingested/room_types.html"
RUNTIME = "results/runtime.csv"
RUNTIME_HTML = "results/runtime.html"
EXPORT = "results/export/{room_type}/{method}/{format}.zip"  # a method's rooms in one format (export.formats)
METHODS = config["generation"]["methods"]
VARIANTS = config["instantiate"]["variants"]
ANNEALING = [m for m in METHODS if planit_methods.get(m).program is not None]  # methods with an energy trace
GENERATORS = planit_methods.graph_sources_of(METHODS)  # the graph generators the methods place graphs of
TABLE3_VARIANTS = [v for v, spec in VARIANTS.items() if spec["graphs"] == "heldout"]
# the placement learners trained: PlanIT's CFCN (Table 3 places with it) and those the methods read
PLACEMENT_NETS = list(dict.fromkeys(["cfcn", *planit_methods.placement_nets_of(METHODS)]))


def keys(*dotted):
    """The config keys a rule's stage reads, as JSON for `planit ... --config-json` (a rerun trigger: the rule
    reruns exactly when one of these keys changes)."""
    return json.dumps(planit_config.pick(config, dotted), sort_keys=True, separators=(",", ":"))


def variant_keys(wildcards):
    """Params function: the keys a Table 3 ablation's search reads (its own variant's spec only)."""
    return keys(*search_keys(config, wildcards.variant))


def generator_train_keys(wildcards):
    """Params function: the keys a graph generator's training reads (sampling settings are not among them: changing
    them resamples without retraining)."""
    return keys(*planit_methods.graph_source(wildcards.generator).train_keys(config))


def generator_sample_keys(wildcards):
    """Params function: the keys a graph generator's sampling reads."""
    return keys(*planit_methods.graph_source(wildcards.generator).sample_keys(config))


def placement_train_keys(wildcards):
    """Params function: the keys a placement learner's training reads."""
    return keys(*planit_methods.placement_learner(wildcards.net).train_keys(config))


def program_train_keys(wildcards):
    """Params function: the keys a program learner reads."""
    return keys(*planit_methods.program_learner(wildcards.program).train_keys(config))


def method_keys(wildcards):
    """Params function: the keys a method reads (adding or changing another method reruns nothing here)."""
    return keys("generation.plugins", *planit_methods.get(wildcards.method).keys(config, wildcards.method))


# Every stage rule runs its subcommand (named as the rule) with its named input and output files as options.
STAGE = "planit {params.io} --config-json {params.config:q} --threads {threads} 2> {log}"
UNPASSED_WILDCARDS = {"corpus"}  # wildcards that only choose paths, not what a stage computes


def stage_io(name):
    """Params function of the rule named ``name``. Gives the subcommand ``name``, then ``--port path`` for each of
    its named inputs (repeated for lists), ``--out-port path`` for each named output, ``--wildcard value`` for the
    wildcards the stage takes; the rule's named files must be exactly the stage's declared ports
    (``pipeline.stages.STAGES``)."""
    if name not in STAGES:
        raise WorkflowError(f"no stage in pipeline.stages.STAGES is named {name} (the rule of that name runs it)")
    stage = STAGES[name]

    def options(wildcards, input, output):
        for kind, ports, files in (("input", stage.inputs, input), ("output", stage.outputs, output)):
            given, declared = set(files.keys()), {p.name for p in ports}
            required = {p.name for p in ports if not p.optional}
            if not required <= given <= declared:
                raise WorkflowError(f"the rule {name} names {kind}s {sorted(given)}, but its stage declares "
                                    f"{sorted(declared)} ({sorted(required)} required)")
        parts = [name]
        for output, ports, files in ((False, stage.inputs, input), (True, stage.outputs, output)):
            for p in ports:
                if p.name in files.keys():
                    value = getattr(files, p.name)
                    paths = [value] if isinstance(value, str) else list(value)
                    parts += [f"{option(p, output)} {shlex.quote(str(v))}" for v in paths]
        parts += [f"--{p.name.replace('_', '-')} {shlex.quote(str(wildcards[p.name]))}" for p in stage.params
                  if p.name in wildcards.keys() and p.name not in UNPASSED_WILDCARDS]
        return " ".join(parts)

    return options


def refuse_folders(rules):
    """Refuse a workflow whose rules read or write a folder; a stage reads and writes files (an archive where it
    writes many). Called once every rule is defined."""
    for r in rules:
        folders = sorted(str(f) for f in [*r.input, *r.output] if is_flagged(f, "directory"))
        if folders:
            raise WorkflowError(f"the rule {r.name} reads or writes folders {folders}; a stage's inputs and "
                                "outputs are files (an archive where it writes many)")


def shards_of(template, **fixed):
    """Every shard's path of a template (a gather's input)."""
    return expand(template, shard=SHARDS, allow_missing=True, **fixed)


# ------------------------------------------------------------------------------------------- corpora
def corpus_path(corpus, table, shard):
    """Canonical table `table` of shard `shard` of a corpus: the ingested rooms kept by the filter, or a folder
    named in config `corpora`."""
    if corpus == "ingested":
        return FILTER_ROOMS.format(shard=shard) if table == "rooms" else INGEST.format(table=table, shard=shard)
    if corpus not in config["corpora"]:
        raise WorkflowError(f"unknown corpus '{corpus}' (config 'corpora' names {sorted(config['corpora'])})")
    return f"{config['corpora'][corpus]}/{table}-{shard}.parquet"


def get_corpus_shard(wildcards):
    """The four canonical tables of one shard of a corpus (extraction's input)."""
    return {t: corpus_path(wildcards.corpus, t, wildcards.shard) for t in ("rooms", "architecture", "objects", "models")}


def get_corpus_models(wildcards):
    return [corpus_path(wildcards.corpus, "models", k) for k in SHARDS]


def get_corpus_ground_truth(wildcards):
    return [corpus_path(wildcards.corpus, "ground_truth", k) for k in SHARDS]


def graph_room_types():
    """The room types learned: the candidates (graph_model.room_types, else the corpus's) that the room_types
    checkpoint kept; the others are skipped with their reason in its table (and the report)."""
    import csv

    with open(checkpoints.room_types.get().output.table) as f:
        return [r["room_type"] for r in csv.DictReader(f) if r["status"] == "learned"]


def get_method_inputs(wildcards):
    """A method's inputs beside the corpus: its graph generator's sampled graphs, the placement networks it reads, its
    reference method's rooms."""
    m = planit_methods.get(wildcards.method)
    out = {}
    if m.graphs is not None:
        out |= {t: GRAPH_MODEL.format(room_type=wildcards.room_type, generator=m.graphs, name=f"sampled/{t}.parquet")
                for t in ("nodes", "edges")}
    if m.model is not None:
        out["model"] = PLACEMENT.format(room_type=wildcards.room_type, net=m.model, name="model.pt")
    if m.program is not None:
        out["program"] = PROGRAM.format(room_type=wildcards.room_type, program=m.program, name="yaml")
    if m.reference is not None:
        out |= {f"reference_{t}": GENERATED.format(room_type=wildcards.room_type, method=m.reference, name=f"{t}.parquet")
                for t in ("rooms", "architecture", "objects", "scenes")}
    return out


def spec_graph_model(wildcards):
    """The graph model of a spec's room type (PlanIT's: the generator that completes partial graphs)."""
    return GRAPH_MODEL.format(room_type=spec_room_type(SPEC_FILE.format(spec=wildcards.spec)), generator="planit",
                              name="model.pt")


def spec_placement(wildcards):
    """The placement networks (CFCN) and the split of a spec's room type."""
    room_type = spec_room_type(SPEC_FILE.format(spec=wildcards.spec))
    return {"model": PLACEMENT.format(room_type=room_type, net="cfcn", name="model.pt"),
            "split": SPLIT.format(room_type=room_type)}


def get_ablation_model(wildcards):
    """A Table 3 variant's placement model: the unconditional networks, the prior, else the conditional networks."""
    location = VARIANTS[wildcards.variant]["location"]
    net = location if location in ("fcn", "prior") else "cfcn"
    return PLACEMENT.format(room_type=wildcards.room_type, net=net, name="model.pt")


# The default run's outputs: those of every corpus stage (known when the workflow is parsed), those of the learned
# room types (known once the room_types checkpoint has run), and the run-time table, built last.
CORPUS_OUTPUTS = [
    ROOM_TYPES,
    FILTER_REPORT,
    INGEST_REPORT,
    DROPS,
    *expand(METRICS, corpus="ingested", name=["extraction", "superstructures"]),
    *expand(REPORT, corpus="ingested", name="table1.csv"),
]


def learned_outputs(wildcards):
    """Input function: the outputs of every learned room type (after the room_types checkpoint)."""
    types = graph_room_types()
    return [
        *expand(GRAPH_MODEL, room_type=types, generator=GENERATORS, name=["metrics.json", "loss.png"]),
        *expand(PLACEMENT, room_type=types, net=PLACEMENT_NETS, name="loss.png"),
        *expand(GENERATED, room_type=types, method=METHODS, name="summary.json"),
        *expand(TABLE3, room_type=[t for t in config["instantiate"]["table3_room_types"] if t in types]),
        *expand(EVAL, room_type=types, name=["metrics.json", "gallery3d.html"]),
        *expand(EVAL, room_type=types, name=["energy_trace.png"] if ANNEALING else []),
        *expand(EXPORT, room_type=types, method=METHODS, format=config["export"]["formats"]),
    ]
