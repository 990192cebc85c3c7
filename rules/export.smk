# Generated rooms in the formats other tools load (docs/formats.md): one archive per room type, method and format
# listed in export.formats (none by default: the default run writes none and is not slowed).


rule export_rooms:
    input:
        **{t: GENERATED.replace("{name}", f"{t}.parquet") for t in ("rooms", "architecture", "objects", "models")},
    output:
        archive=EXPORT,
    params:
        config=keys("export", "ithor"),
        io=stage_io("export_rooms"),
    wildcard_constraints:
        format="usd|procthor|front3d",
    threads: 1
    log:
        "logs/export_rooms/{room_type}-{method}-{format}.log",
    benchmark:
        "benchmarks/export_rooms/{room_type}-{method}-{format}.tsv"
    conda:
        ENV
    shell:
        STAGE
