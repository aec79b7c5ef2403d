#!/usr/bin/env bash
# Where the TRBVH's build time goes on the suite's scenes: every height of every treelet round
# timed as its own stage (TREELET_PROFILE_LEVELS=1), and the plain builds beside.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/T; chmod +x /tmp/T
mkdir -p $OUT/json
scenes="scenes/real/staircase.ply.xz scenes/real/breakfast_room.ply.xz scenes/real/classroom.ply.xz scenes/real/living_room.ply.xz city:300000 city:1000000"
for s in $scenes; do
  n=$(basename $s .ply.xz)
  for k in 1 2 3; do
    /tmp/T build --scene $s --builder trbvh --device gpu --json > $OUT/json/${n}_plain_$k.json || echo "$n plain failed"
    TREELET_PROFILE_LEVELS=1 /tmp/T build --scene $s --builder trbvh --device gpu --json > $OUT/json/${n}_levels_$k.json || echo "$n levels failed"
    TREELET_PROFILE_LEVELS=empty /tmp/T build --scene $s --builder trbvh --device gpu --json > $OUT/json/${n}_empty_$k.json || echo "$n empty failed"
  done
  python3 - $OUT/json/${n}_plain_3.json <<'PY'
import json,sys; d=json.load(open(sys.argv[1])); print(d['scene'], d['adapter'], 'total', round(d['total_ms'],3), {k: round(v,3) for k,v in d['ms'].items() if v}, 'rounds', [round(r,3) for r in d['round_ms']])
PY
done
python3 docs/results/h200-treelet-heights-2026-12-04/heights.py $OUT/json
tar czf $OUT/json.tgz -C $OUT json && rm -r $OUT/json
nvidia-smi --query-gpu=clocks.sm --format=csv
