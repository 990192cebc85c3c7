# PlanIT pipeline. Run: snakemake --cores 2   (profiles/default is picked up automatically)
# --configfile FILE replaces config/config.yaml (keys it leaves out take the schema's defaults).
from snakemake.utils import min_version

min_version("9.0")


configfile: f"{workflow.basedir}/config/config.yaml"


include: "rules/common.smk"
include: "rules/ingest.smk"
include: "rules/extract.smk"
include: "rules/refine.smk"


rule all:
    input:
        get_final_outputs(),
    default_target: True
