# Training graphs: dataset statistics (gather), per-shard refinement, gathered tables, scores, report.


rule graph_statistics:
    input:
        nodes=expand("results/graphs/raw/nodes-{shard}.parquet", shard=SHARDS),
        edges=expand("results/graphs/raw/edges-{shard}.parquet", shard=SHARDS),
    output:
        cooccurrence="results/graphs/stats/cooccurrence.parquet",
        relations="results/graphs/stats/relations.parquet",
        hub_patterns="results/graphs/stats/hub_patterns.parquet",
        category_sizes="results/graphs/stats/category_sizes.parquet",
    params:
        settings=stage_json("refine", "shards"),
    log:
        "logs/graph_statistics/graph_statistics.log",
    benchmark:
        "benchmarks/graph_statistics/graph_statistics.tsv"
    shell:
        "planit graph-stats --config-json {params.settings:q} --raw results/graphs/raw "
        "--out results/graphs/stats 2> {log}"


rule refine_graphs:
    input:
        nodes="results/graphs/raw/nodes-{shard}.parquet",
        edges="results/graphs/raw/edges-{shard}.parquet",
        stats=rules.graph_statistics.output,
    output:
        nodes="results/graphs/final/nodes-{shard}.parquet",
        edges="results/graphs/final/edges-{shard}.parquet",
        superstructures="results/graphs/final/superstructures-{shard}.parquet",
        summary="results/graphs/final/summary-{shard}.json",
    params:
        settings=stage_json("refine"),
    log:
        "logs/refine_graphs/{shard}.log",
    benchmark:
        "benchmarks/refine_graphs/{shard}.tsv"
    shell:
        "planit refine --shard {wildcards.shard} --config-json {params.settings:q} --raw results/graphs/raw "
        "--stats results/graphs/stats --out results/graphs/final 2> {log}"


rule gather_graphs:
    input:
        expand("results/graphs/final/{table}-{shard}.parquet", table=["nodes", "edges", "superstructures"], shard=SHARDS),
    output:
        nodes="results/graphs/nodes.parquet",
        edges="results/graphs/edges.parquet",
        superstructures="results/graphs/superstructures.parquet",
    params:
        settings=stage_json("shards"),
    log:
        "logs/gather_graphs/gather_graphs.log",
    shell:
        "planit gather-graphs --config-json {params.settings:q} --final results/graphs/final --out results/graphs 2> {log}"


rule score_superstructures:
    input:
        ground_truth=rules.ingest.output.ground_truth,
        nodes=rules.gather_graphs.output.nodes,
        superstructures=rules.gather_graphs.output.superstructures,
    output:
        metrics="results/metrics/superstructures.json",
    params:
        settings=stage_json("source", "refine"),
    log:
        "logs/score_superstructures/score_superstructures.log",
    shell:
        "planit score-graphs --config-json {params.settings:q} --ingest results/ingest --graphs results/graphs "
        "--out {output.metrics} 2> {log}"


rule graph_report:
    input:
        rules.gather_graphs.output,
    output:
        table1="results/graphs/report/table1.csv",
        pruning="results/graphs/report/pruning.csv",
        relations="results/graphs/report/relations.csv",
        plot=report("results/graphs/report/graph_stats.png", caption="../docs/report/graph_stats.rst", category="Graphs"),
    log:
        "logs/graph_report/graph_report.log",
    shell:
        "planit stats results/graphs --out results/graphs/report > {log} 2>&1"
