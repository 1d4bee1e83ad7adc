#!/usr/bin/env bash
# The runs behind docs/results/learned/ (issue 23): the learned attacker a user gets on their own
# plant (ARS on the 3 x 2 plant with R_sigma = 10 of docs/results/learned/plant3x2_r10.yaml, the
# old fixed 20M-step budget against the default stopping rule with its plant-scaled budget; the
# default on the design example too) and the PPO recipe of the design example (agents/configs/ppo_paper-example.yaml). Every run is
# evaluated with `encctl-gym evaluate` at the training length N = 256 on the paired seeds
# 20000, ... with 100 and 500 episodes (the margin lines say what each resolves).
# Usage: bash agents/learned_runs.sh [OUT=results/learned] [WHICH=all|ars|ppo]
set -euo pipefail
OUT=${1:-results/learned}
WHICH=${2:-all}
PY=${PYTHON:-python}
PLANT=docs/results/learned/plant3x2_r10.yaml
mkdir -p "$OUT/train" "$OUT/logs" "$OUT/eval"
train() {  # NAME [train options...]
  local name=$1; shift
  /usr/bin/time -f "%e s wall" $PY -m encctl_gym.cli train --seed 0 --out "$OUT/train" --name "$name" --overwrite \
    --no-progress --no-tensorboard "$@" > "$OUT/logs/$name.log" 2>&1
}
evaluate() {  # NAME
  for e in 100 500; do
    /usr/bin/time -f "%e s wall" $PY -m encctl_gym.cli evaluate "$OUT/train/$1" --episodes $e --seed 20000 --points 1 \
      --which best --samples 256 --no-progress --out "$OUT/eval/$1/e$e" > "$OUT/logs/$1.e$e.log" 2>&1
  done
}
if [[ $WHICH == all || $WHICH == ars ]]; then
  train ars_3x2_fixed20M --algo ars --system $PLANT --n-timesteps 20000000 --set stopping.rule=none
  evaluate ars_3x2_fixed20M
  train ars_3x2_default --algo ars --system $PLANT
  evaluate ars_3x2_default
  train ars_pe_default --algo ars --preset paper-example
  evaluate ars_pe_default
fi
if [[ $WHICH == all || $WHICH == ppo ]]; then
  train ppo_pe_recipe --algo ppo --preset paper-example
  evaluate ppo_pe_recipe
fi
