#!/usr/bin/env bash
# The full training runs behind the published comparison, in two lanes on a 2-core machine,
# then their learning curves in one figure and the headline experiment.
# Usage: bash agents/full_runs.sh [OUT=results]
# Each run: encctl-gym train --algo ALGO --preset PRESET --seed 0 --out $OUT/train --overwrite
# (--overwrite: a rerun replaces the runs of the same name instead of adding NAME-2 beside them,
# which compare would also pick up).
set -euo pipefail
OUT=${1:-results}
PY=${PYTHON:-python}
mkdir -p "$OUT/train" "$OUT/logs"
train() { /usr/bin/time -f "%e s wall" $PY -m encctl_gym.cli train --algo "$1" --preset "$2" --seed 0 --out "$OUT/train" --overwrite --no-progress > "$OUT/logs/$1_$2.log" 2>&1; }
( train ppo paper-example; train ppo fig1-c; train ppo fig1-g ) &
( train sac paper-example; train recurrent_ppo paper-example ) &
wait
$PY -m encctl_gym.agents.curves "$OUT"/train/*_s0 --out "$OUT/learning_curves.png" > "$OUT/logs/curves.log" 2>&1
/usr/bin/time -f "%e s wall" $PY -m encctl_gym.cli compare --seed 0 --episodes 50 --runs "$OUT/train" --out "$OUT/compare" > "$OUT/logs/compare.log" 2>&1
