# PlanIT pipeline. Run: snakemake --cores 2   (profiles/default is picked up automatically)
# --configfile FILE extends config/config.yaml: its keys override, the rest come from config/config.yaml.
from snakemake.utils import min_version

min_version("9.0")


configfile: f"{workflow.basedir}/config/config.yaml"


report: "report/workflow.rst"


include: "rules/common.smk"
include: "rules/ingest.smk"
include: "rules/extract.smk"
include: "rules/refine.smk"
include: "rules/graph_model.smk"
include: "rules/instantiate.smk"
include: "rules/evaluate.smk"
include: "rules/export.smk"


rule all:
    input:
        CORPUS_OUTPUTS,
        learned_outputs,
        RUNTIME,
    default_target: True


refuse_folders(workflow.rules)
