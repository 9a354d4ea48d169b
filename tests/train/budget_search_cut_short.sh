#!/bin/sh
# `train --resume --max-gaussians search` after the run was cut short, as kill -9 leaves it:
#   1. in the search: the finished trials are reused (their trial.json), the unfinished one trains again,
#      and budget.json is the uninterrupted search's (the trials are deterministic);
#   2. after the search, before the final training's first checkpoint: the final training starts again at
#      the budget budget.json recorded, without searching;
#   3. a finished trial made with other options (another --seed) is not reused.
# Usage: budget_search_cut_short.sh ENGINE WORKDIR
set -eu
engine=$1
dir=$2
rm -rf "$dir" && mkdir -p "$dir"
"$engine" synth --preset corridor --frames 12 --width 96 --height 80 --out "$dir/scene" > /dev/null
train() {
  "$engine" train "$dir/scene" --max-gaussians search --strategy mcmc --iterations 6 --poses truth \
    --checkpoint-every 3 "$@"
}
fail() { echo "FAIL: $*"; exit 1; }

train --out "$dir/whole" > "$dir/whole.log" 2>&1
grep -v wall_s "$dir/whole/budget.json" > "$dir/whole.json"

# 1. Cut short in the search: no budget.json, no final checkpoint, the last trial without its record.
cp -r "$dir/whole" "$dir/cut"
rm -rf "$dir/cut/budget.json" "$dir/cut/checkpoints" "$dir/cut/metrics.json" "$dir/cut/point_cloud.ply"
last=$(ls -d "$dir"/cut/budget-search/*/fold-1 | sort -V | tail -1)
rm "$last/trial.json"
trials=$(find "$dir/cut/budget-search" -name trial.json | wc -l)
train --out "$dir/cut" --resume > "$dir/cut.log" 2>&1 || fail "resume in the search: $(tail -2 "$dir/cut.log")"
grep -q 'the budget search had not finished; it continues' "$dir/cut.log" || fail "no continuation notice"
reused=$(sed -n 's/.*, \([0-9]*\) of the trainings reused[,)].*/\1/p' "$dir/cut.log" | awk '{s += $1} END {print s + 0}')
[ "$reused" -eq "$trials" ] || fail "reused $reused trainings, $trials had finished"
grep -v wall_s "$dir/cut/budget.json" | diff "$dir/whole.json" - || fail "budget.json differs from the whole run's"
[ -f "$dir/cut/point_cloud.ply" ] || fail "no model after the continued search"

# 2. Cut short after the search: budget.json, but no final checkpoint.
rm -rf "$dir/cut/checkpoints" "$dir/cut/metrics.json"
train --out "$dir/cut" --resume > "$dir/final.log" 2>&1 || fail "resume after the search: $(tail -2 "$dir/final.log")"
grep -q 'budget search on' "$dir/final.log" && fail "searched again though budget.json was there"
budget=$(sed -n 's/^  "gaussians": \([0-9]*\),$/\1/p' "$dir/whole/budget.json")
grep -q "starts again at the searched budget, $budget Gaussians" "$dir/final.log" || fail "no restart at $budget"
size=$(grep '"gaussians":' "$dir/whole/metrics.json")
grep -qF "$size" "$dir/cut/metrics.json" || fail "the final model's size is not the whole run's ($size)"

# 3. Finished trials of another seed: none reused.
rm -rf "$dir/cut/budget.json" "$dir/cut/checkpoints"
train --out "$dir/cut" --resume --seed 5 > "$dir/seed.log" 2>&1 || fail "resume with --seed 5: $(tail -2 "$dir/seed.log")"
grep -q 'trainings reused' "$dir/seed.log" && fail "reused trainings of another seed"
echo "ok: $trials trainings reused, budget $budget"
