#!/bin/bash
# Two commits' workflows timed side by side: each commit in a git worktree of its own (under $TMPDIR, default /tmp),
# run with this checkout's .venv and PYTHONPATH on the worktree, in a fresh work folder, alternating, ROUNDS times.
# Prints the wall clock, the jobs and the summed job time (benchmarks/*.tsv) of each run, then the last round's
# evaluation tables side by side (bench/compare_metrics.py: each figure of the first commit with its 95% interval, the
# second's, and whether it moved outside), so a speed-up that changes outcomes is seen. Run it with nothing else
# running. The default run of two commits: bench/side_by_side.sh A B 1 config/config.yaml all
#   bench/side_by_side.sh be119c2 692fa75 [ROUNDS=2] [CONFIG=config/tiny.yaml] [TARGETS="all results/generated/bedroom/table3.csv"]
set -eu
a=$1; b=$2; rounds=${3:-2}; config=${4:-config/tiny.yaml}; targets=${5:-"all results/generated/bedroom/table3.csv"}
root=$(cd "$(dirname "$0")/.." && pwd); tmp=${TMPDIR:-/tmp}
for rev in $a $b; do
  [ -d "$tmp/sbs_tree_$rev" ] || git -C "$root" worktree add -f "$tmp/sbs_tree_$rev" "$rev" > /dev/null
done
for round in $(seq "$rounds"); do
  for rev in $a $b; do
    work=$tmp/sbs_${rev}_$round; rm -rf "$work"
    start=$(date +%s.%N)
    (cd "$tmp/sbs_tree_$rev" && PATH="$root/.venv/bin:$PATH" PYTHONPATH="$tmp/sbs_tree_$rev" \
      "$root/.venv/bin/snakemake" --directory "$work" --configfile "$config" --cores 2 $targets > "$work.log" 2>&1)
    end=$(date +%s.%N)
    jobs=$(find "$work/benchmarks" -name '*.tsv' | wc -l)
    job_s=$(find "$work/benchmarks" -name '*.tsv' -exec awk 'NR == 2 {print $1}' {} \; | paste -sd+ | bc)
    echo "$rev round $round: wall $(echo "$end - $start" | bc) s, $jobs jobs, job time $job_s s"
  done
done
echo "evaluation, $a (with its 95% intervals) -> $b, round $rounds:"
"$root/.venv/bin/python" "$root/bench/compare_metrics.py" "$tmp/sbs_${a}_$rounds" "$tmp/sbs_${b}_$rounds" || true
