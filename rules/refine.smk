# Training graphs of any corpus: statistics (per-shard map, then gather), per-shard refinement, gathered tables,
# scores and the graph report.


rule shard_statistics:
    input:
        nodes=RAW.replace("{table}", "nodes"),
        edges=RAW.replace("{table}", "edges"),
    output:
        counts=PARTIAL,
        candidates=CANDIDATES,
    params:
        config=keys("refine.hub_min_size_ratio", "refine.chain_min_length", "refine.chain_size_ratio",
                    "refine.chain_collinearity"),
        io=stage_io("shard_statistics"),
    log:
        "logs/shard_statistics/{corpus}-{shard}.log",
    benchmark:
        "benchmarks/shard_statistics/{corpus}-{shard}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule graph_statistics:
    input:
        partial=shards_of(PARTIAL),
        nodes=shards_of(RAW, table="nodes"),
    output:
        **{name: STATS.replace("{name}", name) for name in STAT_TABLES},
    params:
        config=keys("refine.hub_min_pattern_count"),
        io=stage_io("graph_statistics"),
    log:
        "logs/graph_statistics/{corpus}.log",
    benchmark:
        "benchmarks/graph_statistics/{corpus}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule refine_graphs:
    input:
        nodes=RAW.replace("{table}", "nodes"),
        edges=RAW.replace("{table}", "edges"),
        candidates=CANDIDATES,
        relations=STATS.replace("{name}", "relations"),
        hub_patterns=STATS.replace("{name}", "hub_patterns"),
        category_sizes=STATS.replace("{name}", "category_sizes"),
    output:
        nodes=FINAL.replace("{table}", "nodes"),
        edges=FINAL.replace("{table}", "edges"),
        superstructures=FINAL.replace("{table}", "superstructures"),
        summary=FINAL_SUMMARY,
    params:
        config=keys("refine.pruning", "refine.thresholds", "refine.connectivity"),
        io=stage_io("refine_graphs"),
    log:
        "logs/refine_graphs/{corpus}-{shard}.log",
    benchmark:
        "benchmarks/refine_graphs/{corpus}-{shard}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule gather_graphs:
    input:
        nodes=shards_of(FINAL, table="nodes"),
        edges=shards_of(FINAL, table="edges"),
        superstructures=shards_of(FINAL, table="superstructures"),
    output:
        nodes=GATHERED.replace("{table}", "nodes"),
        edges=GATHERED.replace("{table}", "edges"),
        superstructures=GATHERED.replace("{table}", "superstructures"),
    params:
        config=keys(),
        io=stage_io("gather_graphs"),
    log:
        "logs/gather_graphs/{corpus}.log",
    benchmark:
        "benchmarks/gather_graphs/{corpus}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule score_superstructures:
    input:
        nodes=GATHERED.replace("{table}", "nodes"),
        superstructures=GATHERED.replace("{table}", "superstructures"),
        ground_truth=get_corpus_ground_truth,
    output:
        metrics=METRICS.replace("{name}", "superstructures"),
    params:
        config=keys(),
        io=stage_io("score_superstructures"),
    log:
        "logs/score_superstructures/{corpus}.log",
    benchmark:
        "benchmarks/score_superstructures/{corpus}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule graph_report:
    input:
        nodes=GATHERED.replace("{table}", "nodes"),
        edges=GATHERED.replace("{table}", "edges"),
        superstructures=GATHERED.replace("{table}", "superstructures"),
    output:
        table1=REPORT.replace("{name}", "table1.csv"),
        pruning=REPORT.replace("{name}", "pruning.csv"),
        relations=REPORT.replace("{name}", "relations.csv"),
        table1_html=report(REPORT.replace("{name}", "table1.html"), caption="../report/table1.rst", category="2. Graphs",
                           labels={"corpus": "{corpus}", "figure": "Table 1"}),
        pruning_html=report(REPORT.replace("{name}", "pruning.html"), caption="../report/pruning.rst",
                            category="2. Graphs", labels={"corpus": "{corpus}", "figure": "pruning"}),
        plot=report(REPORT.replace("{name}", "graph_stats.png"), caption="../report/graph_stats.rst", category="2. Graphs",
                    labels={"corpus": "{corpus}", "figure": "edges per node"}),
    params:
        config=keys(),
        io=stage_io("graph_report"),
    log:
        "logs/graph_report/{corpus}.log",
    benchmark:
        "benchmarks/graph_report/{corpus}.tsv"
    conda:
        ENV
    shell:
        STAGE
