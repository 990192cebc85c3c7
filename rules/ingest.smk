# Sources -> canonical tables, one job per shard; the ingest summary (gather); room filtering per shard.


rule ingest:
    output:
        **{t: INGEST.replace("{table}", t) for t in INGEST_TABLES},
    params:
        config=keys("seed", "source", "shards", config["source"]),
    log:
        "logs/ingest/{shard}.log",
    benchmark:
        "benchmarks/ingest/{shard}.tsv"
    conda:
        ENV
    shell:
        "planit ingest --shard {wildcards.shard} --config-json {params.config:q} --rooms {output.rooms} "
        "--architecture {output.architecture} --objects {output.objects} --models {output.models} "
        "--ground-truth {output.ground_truth} --report {output.ingest_report} --drops {output.drops} 2> {log}"


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
        rooms=repeat("--rooms", "rooms"),
        objects=repeat("--objects", "objects"),
        models=repeat("--models", "models"),
        reports=repeat("--report", "reports"),
        drops=repeat("--drops", "drops"),
    log:
        "logs/ingest_summary/ingest_summary.log",
    benchmark:
        "benchmarks/ingest_summary/ingest_summary.tsv"
    conda:
        ENV
    shell:
        "planit ingest-summary {params.rooms} {params.objects} {params.models} {params.reports} {params.drops} "
        "--out-counts {output.counts} --out-report {output.report} --out-drops {output.drops} 2> {log}"


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
    log:
        "logs/filter_rooms/{shard}.log",
    benchmark:
        "benchmarks/filter_rooms/{shard}.tsv"
    conda:
        ENV
    shell:
        "planit filter --config-json {params.config:q} --rooms {input.rooms} --architecture {input.architecture} "
        "--objects {input.objects} --models {input.models} --counts {input.counts} --out-rooms {output.rooms} --out-report {output.report} 2> {log}"


rule filter_report:
    input:
        reports=shards_of(FILTER_SHARD_REPORT),
    output:
        report=FILTER_REPORT,
        counts=report(RULE_COUNTS, caption="../report/filter_counts.rst", category="1. Ingest and filter"),
    params:
        reports=repeat("--report", "reports"),
    log:
        "logs/filter_report/filter_report.log",
    benchmark:
        "benchmarks/filter_report/filter_report.tsv"
    conda:
        ENV
    shell:
        "planit filter-report {params.reports} --out-report {output.report} --out-counts {output.counts} > {log} 2>&1"
