#!/bin/bash
# measure62/run.sh RUN: issue 62's figures for an ability-aware platform pair: for each profile
# inside ±20% (not trained on), 20 rule levels and 20 Generator levels at λ = -1 made for it,
# played by the run's Solver and by the scripted expert of that profile (success per level).
set -e
cd /work/trial-runs
B=bin/arlpcg-b6c1617
run=$1
out=measure62/$(basename $run)
mkdir -p $out
base=profiles/low-jump.yaml
for spec in "jump-15:jump_speed:7.86" "jump+15:jump_speed:10.64" "gravity+15:gravity:23.0" "run-15:run_speed:6.8" "jump-20:jump_speed:7.4"; do
  IFS=: read name field value <<< "$spec"
  prof=$out/$name.yaml
  $B profile init --game platform | sed "s/^name: default/name: $name/; s/^\(  $field:\) *[0-9.]*/\1 $value/" > $prof
  rm -rf $out/$name-rules $out/$name-gen
  RAYON_NUM_THREADS=1 $B generate --game platform --rules --profile $prof --count 20 --seed 500 --format yaml --out $out/$name-rules > /dev/null 2>&1
  RAYON_NUM_THREADS=1 $B generate --game platform --policies $run --aux=-1 --profile $prof --count 20 --seed 500 --format yaml --out $out/$name-gen > /dev/null 2>&1 || true
  for who in policy expert; do
    if [ $who = policy ]; then S="--policy $run/solver.safetensors"; else S="--solver scripted-expert"; fi
    RAYON_NUM_THREADS=1 $B verify $S --trials 20 --json $out/$name-rules/*.yaml $out/$name-gen/*.yaml > $out/$name-$who.jsonl 2> $out/$name-$who.err || true
  done
done
python3 measure62/spearman.py $out
