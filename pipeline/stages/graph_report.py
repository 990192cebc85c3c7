"""Graph report (per corpus): Table-1 statistics, pruning by rule and frequent relations as CSV, and one PNG."""
from __future__ import annotations

from ..graphs.report import graph_report, write_report
from ..stage import Files


def run(config: dict, inp: Files, out: Files) -> dict:
    nodes, edges, superstructures = inp.nodes, inp.edges, inp.superstructures
    report = graph_report(nodes, edges, superstructures)
    write_report(report, out)
    return {name: len(df) for name, df in report.items()}
