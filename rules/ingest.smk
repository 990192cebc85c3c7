# Sources -> canonical tables, one job per shard; the ingest summary (gather); room filtering per shard.


rule ingest:
    output:
        **{t: INGEST.replace("{table}", t) for t in INGEST_TABLES},
    params:
        config=keys("seed", "source", "shards", config["source"]),
        io=stage_io("ingest"),
    log:
        "logs/ingest/{shard}.log",
    benchmark:
        "benchmarks/ingest/{shard}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule ingest_summary:
    input:
        rooms=shards_of(INGEST, table="rooms"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        reports=shards_of(INGEST, table="ingest_report"),
        drops=shards_of(INGEST, table="drops"),
    output:
        counts=CATEGORY_COUNTS,
        report=INGEST_REPORT,
        drops=DROPS,
    params:
        config=keys(),
        io=stage_io("ingest_summary"),
    log:
        "logs/ingest_summary/ingest_summary.log",
    benchmark:
        "benchmarks/ingest_summary/ingest_summary.tsv"
    conda:
        ENV
    shell:
        STAGE


rule filter_rooms:
    input:
        rooms=INGEST.replace("{table}", "rooms"),
        architecture=INGEST.replace("{table}", "architecture"),
        objects=INGEST.replace("{table}", "objects"),
        models=INGEST.replace("{table}", "models"),
        counts=CATEGORY_COUNTS,
    output:
        rooms=FILTER_ROOMS,
        report=FILTER_SHARD_REPORT,
    params:
        config=keys("filter", "floor_contact", "extract.backend"),
        io=stage_io("filter_rooms"),
    log:
        "logs/filter_rooms/{shard}.log",
    benchmark:
        "benchmarks/filter_rooms/{shard}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule filter_report:
    input:
        reports=shards_of(FILTER_SHARD_REPORT),
    output:
        report=FILTER_REPORT,
        counts=RULE_COUNTS,
        counts_html=report(RULE_COUNTS_HTML, caption="../report/filter_counts.rst", category="1. Ingest and filter"),
    params:
        config=keys(),
        io=stage_io("filter_report"),
    log:
        "logs/filter_report/filter_report.log",
    benchmark:
        "benchmarks/filter_report/filter_report.tsv"
    conda:
        ENV
    shell:
        STAGE
