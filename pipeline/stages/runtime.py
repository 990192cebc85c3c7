"""Run time of the pipeline (report): Snakemake's benchmark files (``benchmarks/<rule>/<job>.tsv``) gathered per
rule, and the wall-clock span from the first recorded job's start to the last one's end."""
from __future__ import annotations

import csv
import logging
from pathlib import Path

import pandas as pd

from .. import tables
from ..html import write_table_html
from ..stage import Files

log = logging.getLogger("planit.runtime")

WALL, TOTAL = "(wall clock: first job start to last job end)", "(all jobs)"


def read_benchmarks(folder: Path) -> pd.DataFrame:
    """One row per benchmarked job: ``rule``, ``job``, ``seconds``, ``max_rss_mb``, ``end`` (the file's modification
    time, written when the job ended; POSIX seconds). Empty when ``folder`` holds none."""
    rows = []
    for tsv in sorted(Path(folder).glob("*/*.tsv")):
        with tsv.open() as f:
            row = next(csv.DictReader(f, delimiter="\t"), None)
        if row is None:
            continue
        rss = row.get("max_rss", "")
        rows.append({"rule": tsv.parent.name, "job": tsv.stem, "seconds": float(row["s"]),
                     "max_rss_mb": float(rss) if rss not in ("", "NA", "-") else 0.0, "end": tsv.stat().st_mtime})
    return pd.DataFrame(rows, columns=["rule", "job", "seconds", "max_rss_mb", "end"])


def per_rule(jobs: pd.DataFrame) -> pd.DataFrame:
    """Jobs, job seconds, share of all job seconds and peak memory per rule (slowest first), then the total and the
    wall-clock span as two summary rows."""
    g = jobs.groupby("rule").agg(jobs=("job", "size"), job_seconds=("seconds", "sum"), peak_rss_mb=("max_rss_mb", "max"))
    g = g.sort_values("job_seconds", ascending=False).reset_index()
    total = float(g.job_seconds.sum())
    span = float(jobs.end.max() - (jobs.end - jobs.seconds).min()) if len(jobs) else 0.0
    summary = pd.DataFrame({"rule": [WALL, TOTAL], "jobs": [len(jobs)] * 2, "job_seconds": [span, total],
                            "peak_rss_mb": [g.peak_rss_mb.max() if len(g) else 0.0] * 2})
    out = pd.concat([summary, g], ignore_index=True)
    out["share"] = out.job_seconds / max(total, 1e-9)
    out.loc[0, "share"] = float("nan")
    return out.round({"job_seconds": 1, "peak_rss_mb": 0, "share": 3})


def per_method(jobs: pd.DataFrame, rules: dict[str, float]) -> pd.DataFrame:
    """Job seconds per (rule, method) for the rules in ``rules`` whose jobs are named ``<room type>-<method>``: the
    slowest room type's seconds beside the budget ``rules[rule]`` (seconds per method and room type)."""
    picked = jobs[jobs.rule.isin(list(rules)) & jobs.job.str.contains("-")]
    if picked.empty:
        return pd.DataFrame(columns=["rule", "jobs", "job_seconds", "peak_rss_mb", "budget_seconds"])
    method = picked.job.str.split("-", n=1).str[1]
    g = picked.assign(rule=picked.rule + "/" + method).groupby("rule").agg(
        jobs=("job", "size"), job_seconds=("seconds", "sum"), slowest_type=("seconds", "max"),
        peak_rss_mb=("max_rss_mb", "max")).reset_index()
    g["budget_seconds"] = [rules[r.split("/")[0]] for r in g.rule]
    g["over_budget"] = g.slowest_type > g.budget_seconds
    return g.sort_values("job_seconds", ascending=False)


def with_budgets(table: pd.DataFrame, budget: dict) -> pd.DataFrame:
    """``per_rule``'s table with each row's budget (config ``runtime``) and whether the run passed it."""
    rules = {WALL: budget["wall_seconds"], TOTAL: budget["job_seconds"], **budget["rules"]}
    out = table.assign(budget_seconds=[rules.get(r, float("nan")) for r in table.rule])
    out["over_budget"] = out.job_seconds > out.budget_seconds
    return out


def run(config: dict, inp: Files, out: Files, benchmarks: str) -> pd.DataFrame:
    path = out.table
    budget = config["runtime"]
    jobs = read_benchmarks(Path(benchmarks))
    table = with_budgets(per_rule(jobs), budget)
    methods = per_method(jobs, budget["per_method"])
    table = pd.concat([table, methods.drop(columns="slowest_type", errors="ignore")], ignore_index=True)
    tables.write_csv(path, table)
    write_table_html(out.table_html, table, "Run time per rule, against its budget",
                     f"The wall-clock span, all job seconds, then per rule (slowest first), each beside its budget "
                     f"(config runtime, docs/benchmarks.md); then per method within "
                     f"{', '.join(budget['per_method'])} (budget: seconds per method and room type). The same rows "
                     f"are in {path.name}.", notes={"share": "share of all job seconds",
                                                   "over_budget": "job seconds above the budget"})
    for row in table.head(8).itertuples(index=False):
        log.info("  %-48s %4d jobs %8.1f s (budget %s)", row.rule, row.jobs, row.job_seconds, row.budget_seconds)
    return table
