# Config validation and helpers shared by every rule file (no lambdas in rules).
import json

from snakemake.utils import validate


validate(config, schema="../config/schema.yaml")

SHARDS = list(range(config["shards"]))


def stage_json(*sections):
    """The config sections a stage reads, as JSON for `planit ... --config-json`.

    Passing only its own sections to each rule makes Snakemake rerun a stage (and what depends on it)
    exactly when those sections change (params are a rerun trigger).
    """
    return json.dumps({s: config[s] for s in sections}, sort_keys=True, separators=(",", ":"))


def get_final_outputs():
    return [
        "results/filter/report.parquet",
        "results/metrics/extraction.json",
        "results/metrics/superstructures.json",
        "results/graphs/report/table1.csv",
    ]
