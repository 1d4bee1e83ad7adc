#!/usr/bin/env bash
# The learned attackers behind the README's headline table (issue 15): paired ARS with the dither
# feature (agents/configs/defaults/ars.yaml, tuned with encctl-gym tune) on the design example and
# on Figure 1 (c), with states (decipher_delay = 0) and blind (decipher_delay = end, the
# agents/configs/blind/ars.yaml overrides), each evaluated on 100 paired seeds against the
# Gaussian, AR(1) and oracle attackers at the training attack length (N = 256) and at the full
# tau_c budget. One lane (ARS batches its candidates in one vector env on one core).
# Usage: bash agents/ars_runs.sh [OUT=results/ars]
set -euo pipefail
OUT=${1:-results/ars}
PY=${PYTHON:-python}
mkdir -p "$OUT/train" "$OUT/logs" "$OUT/eval"
run() {  # NAME PRESET [train options...]
  local name=$1 preset=$2; shift 2
  /usr/bin/time -f "%e s wall" $PY -m encctl_gym.cli train --algo ars --preset "$preset" --seed 0 --out "$OUT/train" \
    --name "$name" --overwrite --no-progress --no-tensorboard "$@" > "$OUT/logs/$name.log" 2>&1
  for how in "--samples 256:samples256" "--full-budget:fullbudget"; do
    /usr/bin/time -f "%e s wall" $PY -m encctl_gym.cli evaluate "$OUT/train/$name" --episodes 100 --seed 20000 --points 1 \
      --which best ${how%%:*} --no-progress --out "$OUT/eval/$name/${how##*:}" > "$OUT/logs/$name.${how##*:}.log" 2>&1
  done
}
run ars_pe paper-example
run ars_pe_100M_lin paper-example --n-timesteps 100000000 --set hyperparams.learning_rate=lin_0.02
run ars_f1c fig1-c
run ars_pe_blind paper-example --config agents/configs/blind/ars.yaml
run ars_f1c_blind fig1-c --config agents/configs/blind/ars.yaml
