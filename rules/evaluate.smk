# Evaluation: the rooms of every method of generation.methods and the held-out real rooms of one room type scored by
# the same metrics (results/eval/<type>/metrics.json and one row per scene).


rule evaluate:
    input:
        summaries=expand(GENERATED, method=METHODS, name="summary.json", allow_missing=True),
        generated_rooms=expand(GENERATED, method=METHODS, name="rooms.parquet", allow_missing=True),
        generated_architecture=expand(GENERATED, method=METHODS, name="architecture.parquet", allow_missing=True),
        generated_objects=expand(GENERATED, method=METHODS, name="objects.parquet", allow_missing=True),
        generated_scenes=expand(GENERATED, method=METHODS, name="scenes.parquet", allow_missing=True),
        generated_archives=expand(GENERATED, method=METHODS, name="scenes.zip", allow_missing=True),
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        split=SPLIT,
        symmetry=SYMMETRY.format(corpus="ingested"),
    output:
        metrics=EVAL.replace("{name}", "metrics.json"),
        scenes=EVAL.replace("{name}", "scenes.parquet"),
        table=EVAL.replace("{name}", "metrics.csv"),
        table_html=report(EVAL.replace("{name}", "metrics.html"), caption="../report/evaluation.rst",
                          category="5. Evaluation", subcategory="{room_type}",
                          labels={"room type": "{room_type}", "figure": "metrics"}),
        power=report(EVAL.replace("{name}", "power.png"), caption="../report/power.rst", category="5. Evaluation",
                     subcategory="{room_type}", labels={"room type": "{room_type}", "figure": "classifier power"}),
        gallery=report(EVAL.replace("{name}", "gallery.png"), caption="../report/gallery.rst", category="6. Gallery",
                       subcategory="{room_type}", labels={"room type": "{room_type}", "figure": "gallery"}),
    params:
        config=keys("seed", "source", "extract", "floor_contact", "evaluate"),
        io=stage_io("evaluate"),
    threads: 1
    log:
        "logs/evaluate/{room_type}.log",
    benchmark:
        "benchmarks/evaluate/{room_type}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule gallery_3d:
    input:
        generated_scenes=expand(GENERATED, method=METHODS, name="scenes.parquet", allow_missing=True),
        generated_rooms=expand(GENERATED, method=METHODS, name="rooms.parquet", allow_missing=True),
        generated_architecture=expand(GENERATED, method=METHODS, name="architecture.parquet", allow_missing=True),
        generated_objects=expand(GENERATED, method=METHODS, name="objects.parquet", allow_missing=True),
        generated_models=expand(GENERATED, method=METHODS, name="models.parquet", allow_missing=True),
        sampled_nodes=expand(GRAPH_MODEL, generator=GENERATORS, name="sampled/nodes.parquet", allow_missing=True),
        sampled_edges=expand(GRAPH_MODEL, generator=GENERATORS, name="sampled/edges.parquet", allow_missing=True),
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        split=SPLIT,
    output:
        page=report(EVAL.replace("{name}", "gallery3d.html"), caption="../report/gallery3d.rst", category="6. Gallery",
                    subcategory="{room_type}", labels={"room type": "{room_type}", "figure": "3D gallery"}),
    params:
        config=keys("seed", "extract", "floor_contact", "evaluate.gallery", "generation.plugins"),
        io=stage_io("gallery_3d"),
    threads: 1
    log:
        "logs/gallery_3d/{room_type}.log",
    benchmark:
        "benchmarks/gallery_3d/{room_type}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule energy_trace:
    input:
        generated_scenes=expand(GENERATED, method=ANNEALING, name="scenes.parquet", allow_missing=True),
        summaries=expand(GENERATED, method=ANNEALING, name="summary.json", allow_missing=True),
    output:
        figure=report(EVAL.replace("{name}", "energy_trace.png"), caption="../report/energy_trace.rst",
                      category="5. Evaluation", subcategory="{room_type}",
                      labels={"room type": "{room_type}", "figure": "energy trace"}),
    params:
        config=keys("seed"),
        io=stage_io("energy_trace"),
    log:
        "logs/energy_trace/{room_type}.log",
    benchmark:
        "benchmarks/energy_trace/{room_type}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule runtime:
    input:
        corpus=CORPUS_OUTPUTS,
        learned=learned_outputs,
    output:
        table=RUNTIME,
        table_html=report(RUNTIME_HTML, caption="../report/runtime.rst", category="7. Run time"),
    params:
        config=keys("runtime"),
        io=stage_io("runtime"),
    log:
        "logs/runtime/runtime.log",
    conda:
        ENV
    shell:
        STAGE
