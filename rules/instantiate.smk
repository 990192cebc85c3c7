# Generation: train PlanIT's placement networks per room type; generate rooms with every method of
# generation.methods (the method wildcard); place the held-out rooms' graphs under Table 3's ablations and gather
# Table 3.


rule train_placement:
    input:
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        split=SPLIT,
    output:
        model=PLACEMENT.replace("{name}", "model.pt"),
        history=PLACEMENT.replace("{name}", "history.csv"),
        curve=report(PLACEMENT.replace("{name}", "loss.png"), caption="../report/placement_loss.rst",
                     category="3. Training", subcategory="placement networks",
                     labels={"room type": "{room_type}", "network": "{net}"}),
        summary=PLACEMENT.replace("{name}", "training.json"),
    params:
        config=placement_train_keys,
        io=stage_io("train_placement"),
    threads: 1  # more per job: set-threads in a profile
    resources:
        gpu=1 if config["placement"]["device"] == "cuda" else 0,
    log:
        "logs/train_placement/{room_type}-{net}.log",
    benchmark:
        "benchmarks/train_placement/{room_type}-{net}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule learn_program:
    input:
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        split=SPLIT,
    output:
        program=report(PROGRAM.replace("{name}", "yaml"), caption="../report/program.rst", category="3. Training",
                       subcategory="programs", labels={"room type": "{room_type}", "program": "{program}"}),
        summary=PROGRAM.replace("{name}", "json"),
    params:
        config=program_train_keys,
        io=stage_io("learn_program"),
    log:
        "logs/learn_program/{room_type}-{program}.log",
    benchmark:
        "benchmarks/learn_program/{room_type}-{program}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule generate:
    input:
        unpack(get_method_inputs),
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        split=SPLIT,
        symmetry=SYMMETRY.format(corpus="ingested"),
        category_sizes=STATS.format(corpus="ingested", name="category_sizes"),
    output:
        **{t: GENERATED.replace("{name}", f"{t}.parquet") for t in ("rooms", "architecture", "objects", "models", "scenes")},
        summary=GENERATED.replace("{name}", "summary.json"),
        archive=GENERATED.replace("{name}", "scenes.zip"),
    params:
        config=method_keys,
        io=stage_io("generate"),
    threads: 1
    log:
        "logs/generate/{room_type}-{method}.log",
    benchmark:
        "benchmarks/generate/{room_type}-{method}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule instantiate:
    input:
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        model=get_ablation_model,
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        split=SPLIT,
        symmetry=SYMMETRY.format(corpus="ingested"),
        category_sizes=STATS.format(corpus="ingested", name="category_sizes"),
    output:
        **{t: ABLATION.replace("{name}", f"{t}.parquet") for t in ("rooms", "architecture", "objects", "models", "scenes")},
        summary=ABLATION.replace("{name}", "summary.json"),
        archive=ABLATION.replace("{name}", "scenes.zip"),
    params:
        config=variant_keys,
        io=stage_io("instantiate"),
    threads: 1
    log:
        "logs/instantiate/{room_type}-{variant}.log",
    benchmark:
        "benchmarks/instantiate/{room_type}-{variant}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule place_graphs:
    input:
        unpack(spec_placement),
        nodes=SPEC.replace("{name}", "graphs/nodes.parquet"),
        edges=SPEC.replace("{name}", "graphs/edges.parquet"),
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        symmetry=SYMMETRY.format(corpus="ingested"),
        category_sizes=STATS.format(corpus="ingested", name="category_sizes"),
    output:
        **{t: SPEC.replace("{name}", f"{t}.parquet") for t in ("rooms", "architecture", "objects", "models", "scenes")},
        summary=SPEC.replace("{name}", "summary.json"),
        archive=SPEC.replace("{name}", "scenes.zip"),
    params:
        config=keys(*search_keys(config, "planit")),
        io=stage_io("place_graphs"),
    threads: 1
    log:
        "logs/place_graphs/{spec}.log",
    benchmark:
        "benchmarks/place_graphs/{spec}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule complete_room:
    input:
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        model=PLACEMENT.replace("{net}", "cfcn").replace("{name}", "model.pt"),
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        split=SPLIT,
        symmetry=SYMMETRY.format(corpus="ingested"),
        category_sizes=STATS.format(corpus="ingested", name="category_sizes"),
    output:
        **{t: COMPLETE.replace("{name}", f"{t}.parquet") for t in ("rooms", "architecture", "objects", "models", "scenes")},
        summary=COMPLETE.replace("{name}", "summary.json"),
        archive=COMPLETE.replace("{name}", "scenes.zip"),
    params:
        config=keys(*search_keys(config, "heldout")),
        io=stage_io("complete_room"),
    threads: 1
    log:
        "logs/complete_room/{room_type}-{room}-{keep}.log",
    benchmark:
        "benchmarks/complete_room/{room_type}-{room}-{keep}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule table3:
    input:
        summaries=expand(ABLATION, variant=TABLE3_VARIANTS, name="summary.json", allow_missing=True),
        nets=expand(PLACEMENT, net=["cfcn", "fcn"], name="training.json", allow_missing=True),
    output:
        table=TABLE3,
        table_html=report(TABLE3_HTML, caption="../report/table3.rst", category="4. Instantiation (Table 3)",
                          labels={"room type": "{room_type}"}),
    params:
        config=keys(),
        io=stage_io("table3"),
    log:
        "logs/table3/{room_type}.log",
    benchmark:
        "benchmarks/table3/{room_type}.tsv"
    conda:
        ENV
    shell:
        STAGE
