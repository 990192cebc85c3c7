# Instantiation (PlanIT section 6): train the placement networks per room type, place sampled graphs (variant
# planit) and the held-out rooms' graphs under Table 3's ablations, and gather Table 3.


rule train_placement:
    input:
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
    output:
        model=PLACEMENT.replace("{name}", "model.pt"),
        history=PLACEMENT.replace("{name}", "history.csv"),
        curve=report(PLACEMENT.replace("{name}", "loss.png"), caption="../report/placement_loss.rst",
                     category="3. Training", subcategory="placement networks",
                     labels={"room type": "{room_type}", "network": "{net}"}),
        summary=PLACEMENT.replace("{name}", "training.json"),
    params:
        config=keys("seed", "graph_model.heldout_fraction", *(f"placement.{k}" for k in PLACEMENT_TRAIN_KEYS)),
        rooms=repeat("--rooms", "rooms"),
        architecture=repeat("--architecture", "architecture"),
        objects=repeat("--objects", "objects"),
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
        "planit train-placement --config-json {params.config:q} --room-type {wildcards.room_type} --net {wildcards.net} "
        "--threads {threads} {params.rooms} {params.architecture} {params.objects} --nodes {input.nodes} "
        "--edges {input.edges} --out-model {output.model} --out-history {output.history} --out-curve {output.curve} "
        "--out-summary {output.summary} 2> {log}"


rule instantiate:
    input:
        unpack(get_instantiate_inputs),
        rooms=shards_of(FILTER_ROOMS),
        architecture=shards_of(INGEST, table="architecture"),
        objects=shards_of(INGEST, table="objects"),
        models=shards_of(INGEST, table="models"),
        symmetry=SYMMETRY.format(corpus="ingested"),
        category_sizes=STATS.format(corpus="ingested", name="category_sizes"),
    output:
        rooms=GENERATED.replace("{name}", "rooms.parquet"),
        architecture=GENERATED.replace("{name}", "architecture.parquet"),
        objects=GENERATED.replace("{name}", "objects.parquet"),
        models=GENERATED.replace("{name}", "models.parquet"),
        scenes=GENERATED.replace("{name}", "scenes.parquet"),
        summary=GENERATED.replace("{name}", "summary.json"),
        files=directory(GENERATED.replace("{name}", "scenes")),
    params:
        config=instantiate_keys,
        rooms=repeat("--rooms", "rooms"),
        architecture=repeat("--architecture", "architecture"),
        objects=repeat("--objects", "objects"),
        models=repeat("--models", "models"),
        folder=subpath(output.summary, parent=True),
    threads: 1
    log:
        "logs/instantiate/{room_type}-{variant}.log",
    benchmark:
        "benchmarks/instantiate/{room_type}-{variant}.tsv"
    conda:
        ENV
    shell:
        "planit instantiate --config-json {params.config:q} --room-type {wildcards.room_type} "
        "--variant {wildcards.variant} --threads {threads} --nodes {input.nodes} --edges {input.edges} --model {input.model} "
        "{params.rooms} {params.architecture} {params.objects} {params.models} --symmetry {input.symmetry} "
        "--category-sizes {input.category_sizes} --out {params.folder} 2> {log}"


rule table3:
    input:
        summaries=expand(GENERATED, variant=TABLE3_VARIANTS, name="summary.json", allow_missing=True),
    output:
        table=report(TABLE3, caption="../report/table3.rst", category="4. Instantiation (Table 3)",
                     labels={"room type": "{room_type}"}),
    params:
        summaries=repeat("--summary", "summaries"),
    log:
        "logs/table3/{room_type}.log",
    benchmark:
        "benchmarks/table3/{room_type}.tsv"
    conda:
        ENV
    shell:
        "planit table3 {params.summaries} --out {output.table} 2> {log}"
