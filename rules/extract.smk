# Raw relation graphs: model symmetry (gather), per-shard Embree extraction, scores against ground truth.


rule symmetry:
    input:
        models=rules.ingest.output.models,
    output:
        table="results/symmetry/symmetry.parquet",
        agreement="results/symmetry/agreement.json",
    params:
        settings=stage_json("seed", "extract"),
    log:
        "logs/symmetry/symmetry.log",
    benchmark:
        "benchmarks/symmetry/symmetry.tsv"
    shell:
        "planit symmetry --config-json {params.settings:q} --ingest results/ingest --out results/symmetry 2> {log}"


rule extract_graphs:
    input:
        rooms=rules.filter_rooms.output.rooms,
        architecture=rules.ingest.output.architecture,
        objects=rules.ingest.output.objects,
        models=rules.ingest.output.models,
        symmetry=rules.symmetry.output.table,
    output:
        nodes="results/graphs/raw/nodes-{shard}.parquet",
        edges="results/graphs/raw/edges-{shard}.parquet",
        summary="results/graphs/raw/summary-{shard}.json",
    params:
        settings=stage_json("extract"),
    log:
        "logs/extract_graphs/{shard}.log",
    benchmark:
        "benchmarks/extract_graphs/{shard}.tsv"
    shell:
        "planit extract --shard {wildcards.shard} --config-json {params.settings:q} --ingest results/ingest "
        "--filter results/filter --symmetry {input.symmetry} --out results/graphs/raw 2> {log}"


rule score_extraction:
    input:
        ground_truth=rules.ingest.output.ground_truth,
        edges=expand("results/graphs/raw/edges-{shard}.parquet", shard=SHARDS),
        nodes=expand("results/graphs/raw/nodes-{shard}.parquet", shard=SHARDS),
    output:
        metrics="results/metrics/extraction.json",
    params:
        settings=stage_json("source", "shards"),
    log:
        "logs/score_extraction/score_extraction.log",
    shell:
        "planit score --config-json {params.settings:q} --ingest results/ingest --raw results/graphs/raw "
        "--out {output.metrics} 2> {log}"
