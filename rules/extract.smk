# Raw relation graphs of any corpus: model symmetry (gather), per-shard Embree extraction, scores against ground truth.


rule symmetry:
    input:
        models=get_corpus_models,
    output:
        table=SYMMETRY,
        agreement=SYMMETRY_AGREEMENT,
    params:
        config=keys("seed", "extract.symmetry"),
        models=repeat("--models", "models"),
    log:
        "logs/symmetry/{corpus}.log",
    benchmark:
        "benchmarks/symmetry/{corpus}.tsv"
    conda:
        ENV
    shell:
        "planit symmetry --config-json {params.config:q} {params.models} --out-table {output.table} "
        "--out-agreement {output.agreement} 2> {log}"


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
    log:
        "logs/extract_graphs/{corpus}-{shard}.log",
    benchmark:
        "benchmarks/extract_graphs/{corpus}-{shard}.tsv"
    conda:
        ENV
    shell:
        "planit extract --shard {wildcards.shard} --config-json {params.config:q} --rooms {input.rooms} "
        "--architecture {input.architecture} --objects {input.objects} --models {input.models} "
        "--symmetry {input.symmetry} --out-nodes {output.nodes} --out-edges {output.edges} "
        "--out-summary {output.summary} 2> {log}"


rule score_extraction:
    input:
        nodes=shards_of(RAW, table="nodes"),
        edges=shards_of(RAW, table="edges"),
        ground_truth=get_corpus_ground_truth,
    output:
        metrics=METRICS.replace("{name}", "extraction"),
    params:
        nodes=repeat("--nodes", "nodes"),
        edges=repeat("--edges", "edges"),
        ground_truth=repeat("--ground-truth", "ground_truth"),
    log:
        "logs/score_extraction/{corpus}.log",
    benchmark:
        "benchmarks/score_extraction/{corpus}.tsv"
    conda:
        ENV
    shell:
        "planit score {params.nodes} {params.edges} {params.ground_truth} --out {output.metrics} > {log} 2>&1"
