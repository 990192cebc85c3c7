#!/bin/bash
# make test's pytest run side by side at two commits, each from its git worktree (bench/side_by_side.sh makes them:
# $TMPDIR/sbs_tree_<rev>), with --durations=0 so that the tests both commits hold can be compared one by one
# (bench/test_durations.py). Subprocesses that the tests start with a bare environment import the package through the
# editable install, so its mapping points at each worktree for the duration and is put back at the end.
#   bench/test_side_by_side.sh be119c2 692fa75
set -u
root=$(cd "$(dirname "$0")/.." && pwd); tmp=${TMPDIR:-/tmp}
F=$(ls "$root"/.venv/lib/python3*/site-packages/__editable___planit_pipeline_*_finder.py)
cp "$F" "$tmp/finder.bak"
trap 'cp "$tmp/finder.bak" "$F"' EXIT
for rev in "$@"; do
  [ -d "$tmp/sbs_tree_$rev" ] || git -C "$root" worktree add -f "$tmp/sbs_tree_$rev" "$rev" > /dev/null
  sed -i "s#'pipeline': '[^']*'#'pipeline': '$tmp/sbs_tree_$rev/pipeline'#" "$F"
  start=$(date +%s.%N)
  (cd "$tmp/sbs_tree_$rev" && PLANIT_SHARED_DATA="$root/../shared/data" PATH="$root/.venv/bin:$PATH" \
    PYTHONPATH="$tmp/sbs_tree_$rev" "$root/.venv/bin/python" -m pytest -q -ra -n 2 --dist loadgroup --durations=0 \
    -p no:cacheprovider > "$tmp/test_sbs_$rev.log" 2>&1)
  echo "$rev: wall $(echo "$(date +%s.%N) - $start" | bc) s; $(tail -1 "$tmp/test_sbs_$rev.log")"
done
