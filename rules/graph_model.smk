# The graph generative model (PlanIT section 5), one per room type: train on the final graphs of the ingested
# corpus, sample graphs in held-out rooms' architectures, evaluate them against the held-out graphs. The split of a
# room type's rooms is written once (split_rooms) and read by every learner, method and the evaluation.


checkpoint room_types:
    input:
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
    output:
        table=ROOM_TYPES,
        table_html=report(ROOM_TYPES_HTML, caption="../report/room_types.rst", category="2. Graphs",
                          labels={"corpus": "ingested", "figure": "room types"}),
    params:
        config=keys("graph_model.room_types", "source", "procedural.rooms", "filter.min_floor_objects"),
        io=stage_io("room_types"),
    log:
        "logs/room_types/room_types.log",
    benchmark:
        "benchmarks/room_types/room_types.tsv"
    conda:
        ENV
    shell:
        STAGE


rule split_rooms:
    input:
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
    output:
        split=SPLIT,
    params:
        config=keys("seed", "graph_model.heldout_fraction", "graph_model.validation_fraction"),
        io=stage_io("split_rooms"),
    log:
        "logs/split_rooms/{room_type}.log",
    benchmark:
        "benchmarks/split_rooms/{room_type}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule train_graph_model:
    input:
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        split=SPLIT,
    output:
        model=GRAPH_MODEL.replace("{name}", "model.pt"),
        history=GRAPH_MODEL.replace("{name}", "history.csv"),
        curve=report(GRAPH_MODEL.replace("{name}", "loss.png"), caption="../report/graph_model_loss.rst",
                     category="3. Training", subcategory="graph model",
                     labels={"room type": "{room_type}", "generator": "{generator}"}),
        summary=GRAPH_MODEL.replace("{name}", "training.json"),
    params:
        config=generator_train_keys,
        io=stage_io("train_graph_model"),
    threads: 1  # more per job: set-threads in a profile
    resources:
        gpu=lambda wildcards: int(config[planit_methods.graph_source(wildcards.generator).section]["device"] == "cuda"),
    log:
        "logs/train_graph_model/{room_type}-{generator}.log",
    benchmark:
        "benchmarks/train_graph_model/{room_type}-{generator}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule sample_graphs:
    input:
        model=GRAPH_MODEL.replace("{name}", "model.pt"),
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
    output:
        nodes=GRAPH_MODEL.replace("{name}", "sampled/nodes.parquet"),
        edges=GRAPH_MODEL.replace("{name}", "sampled/edges.parquet"),
        summary=GRAPH_MODEL.replace("{name}", "sampled/summary.json"),
    params:
        config=generator_sample_keys,
        io=stage_io("sample_graphs"),
    threads: 1
    log:
        "logs/sample_graphs/{room_type}-{generator}.log",
    benchmark:
        "benchmarks/sample_graphs/{room_type}-{generator}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule graph_model_metrics:
    input:
        model=GRAPH_MODEL.replace("{name}", "model.pt"),
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        gen_nodes=GRAPH_MODEL.replace("{name}", "sampled/nodes.parquet"),
        gen_edges=GRAPH_MODEL.replace("{name}", "sampled/edges.parquet"),
        sample_summary=GRAPH_MODEL.replace("{name}", "sampled/summary.json"),
    output:
        metrics=GRAPH_MODEL.replace("{name}", "metrics.json"),
    params:
        config=keys("seed", "source"),
        io=stage_io("graph_model_metrics"),
    log:
        "logs/graph_model_metrics/{room_type}-{generator}.log",
    benchmark:
        "benchmarks/graph_model_metrics/{room_type}-{generator}.tsv"
    conda:
        ENV
    shell:
        STAGE


rule complete_graphs:
    input:
        model=spec_graph_model,
        nodes=GATHERED.format(corpus="ingested", table="nodes"),
        edges=GATHERED.format(corpus="ingested", table="edges"),
        spec_file=SPEC_FILE,
    output:
        nodes=SPEC.replace("{name}", "graphs/nodes.parquet"),
        edges=SPEC.replace("{name}", "graphs/edges.parquet"),
        summary=SPEC.replace("{name}", "graphs/summary.json"),
    params:
        config=keys("seed", "graph_model.sample"),
        io=stage_io("complete_graphs"),
    threads: 1
    log:
        "logs/complete_graphs/{spec}.log",
    benchmark:
        "benchmarks/complete_graphs/{spec}.tsv"
    conda:
        ENV
    shell:
        STAGE
