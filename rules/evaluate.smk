# Evaluation (evaluation issue): the default generated rooms, the baselines and the held-out real rooms of one room
# type scored by the same metrics (results/eval/<type>/metrics.json and one row per scene).


rule evaluate:
    input:
        summaries=expand(GENERATED, variant=EVAL_SETS, name="summary.json", allow_missing=True),
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        symmetry=SYMMETRY.format(corpus="ingested"),
    output:
        metrics=EVAL.replace("{name}", "metrics.json"),
        scenes=EVAL.replace("{name}", "scenes.parquet"),
        table=report(EVAL.replace("{name}", "metrics.csv"), caption="../report/evaluation.rst", category="5. Evaluation",
                     subcategory="{room_type}", labels={"room type": "{room_type}", "figure": "metrics"}),
        gallery=report(directory(EVAL.replace("{name}", "gallery")), patterns=["{name}.png"],
                       caption="../report/gallery.rst", category="6. Gallery", subcategory="{room_type}",
                       labels={"room type": "{room_type}", "room": "{name}"}),
    params:
        config=keys("seed", "source", "graph_model.heldout_fraction", "extract", "floor_contact", "evaluate"),
        generated=generated_options,
        rooms=repeat("--rooms", "rooms"),
        architecture=repeat("--architecture", "architecture"),
        objects=repeat("--objects", "objects"),
        models=repeat("--models", "models"),
    threads: 1
    log:
        "logs/evaluate/{room_type}.log",
    benchmark:
        "benchmarks/evaluate/{room_type}.tsv"
    conda:
        ENV
    shell:
        "planit evaluate --config-json {params.config:q} --room-type {wildcards.room_type} {params.generated} "
        "{params.rooms} {params.architecture} {params.objects} {params.models} --nodes {input.nodes} --edges {input.edges} "
        "--symmetry {input.symmetry} "
        "--out-metrics {output.metrics} --out-scenes {output.scenes} --out-table {output.table} "
        "--out-gallery {output.gallery} --threads {threads} 2> {log}"


rule runtime:
    input:
        pipeline_outputs(),
    output:
        table=report(RUNTIME, caption="../report/runtime.rst", category="7. Run time"),
    log:
        "logs/runtime/runtime.log",
    conda:
        ENV
    shell:
        "planit runtime --benchmarks benchmarks --out {output.table} 2> {log}"
