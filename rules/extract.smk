# Raw relation graphs of any corpus: model symmetry (gather), per-shard Embree extraction, scores against ground truth.


rule symmetry:
    input:
        models=get_corpus_models,
    output:
        table=SYMMETRY,
        agreement=SYMMETRY_AGREEMENT,
    params:
        config=keys("seed", "extract.symmetry"),
        io=stage_io("symmetry"),
    log:
        "logs/symmetry/{corpus}.log",
    benchmark:
        "benchmarks/symmetry/{corpus}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule extract_graphs:
    input:
        unpack(get_corpus_shard),
        symmetry=SYMMETRY,
    output:
        nodes=RAW.replace("{table}", "nodes"),
        edges=RAW.replace("{table}", "edges"),
        summary=RAW_SUMMARY,
    params:
        config=keys("extract.backend", "extract.support", "extract.spatial", "extract.distance", "extract.architecture",
                    "floor_contact"),
        io=stage_io("extract_graphs"),
    log:
        "logs/extract_graphs/{corpus}-{shard}.log",
    benchmark:
        "benchmarks/extract_graphs/{corpus}-{shard}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule score_extraction:
    input:
        nodes=shards_of(RAW, table="nodes"),
        edges=shards_of(RAW, table="edges"),
        ground_truth=get_corpus_ground_truth,
    output:
        metrics=METRICS.replace("{name}", "extraction"),
    params:
        config=keys(),
        io=stage_io("score_extraction"),
    log:
        "logs/score_extraction/{corpus}.log",
    benchmark:
        "benchmarks/score_extraction/{corpus}.tsv"
    conda:
        ENV
    shell:
        STAGE
