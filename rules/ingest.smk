# Sources -> canonical tables; room filtering and sharding.


rule ingest:
    output:
        rooms="results/ingest/rooms.parquet",
        architecture="results/ingest/architecture.parquet",
        objects="results/ingest/objects.parquet",
        models="results/ingest/models.parquet",
        ground_truth="results/ingest/ground_truth.parquet",
        report="results/ingest/ingest_report.parquet",
    params:
        settings=stage_json("seed", "source", config["source"]),
    log:
        "logs/ingest/ingest.log",
    benchmark:
        "benchmarks/ingest/ingest.tsv"
    shell:
        "planit ingest --config-json {params.settings:q} --out results/ingest 2> {log}"


rule filter_rooms:
    input:
        rooms=rules.ingest.output.rooms,
        architecture=rules.ingest.output.architecture,
        objects=rules.ingest.output.objects,
    output:
        rooms="results/filter/rooms.parquet",
        report="results/filter/report.parquet",
        counts="results/filter/rule_counts.tsv",
    params:
        settings=stage_json("filter", "shards"),
    log:
        "logs/filter_rooms/filter_rooms.log",
    benchmark:
        "benchmarks/filter_rooms/filter_rooms.tsv"
    shell:
        "planit filter --config-json {params.settings:q} --ingest results/ingest --out results/filter 2> {log}"
