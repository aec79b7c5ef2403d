#!/usr/bin/env bash
# Reinsertion: per-kernel times, searches bounded in climb (TREELET_REINSERT_CLIMB), GPU tree against the CPU runner's.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
T=/tmp/treelet
echo "== per kernel, 1M random spheres, trbvh + reinsert 4"
$T bench build --builder trbvh --reinsert 4 --sizes 1000000 --repeats 3 --per-kernel 2>&1 | grep -v "^\s*$" | tail -40
echo "== GPU against CPU runner (SAH of the same build; equal trees give equal SAH)"
for s in city:30000 scenes/real/classroom.ply.xz; do for d in gpu cpu; do
  echo "$s $d $(TREELET_SPLITS=0 $T build --scene $s --builder trbvh --reinsert 4 --device $d --json | python3 -c 'import json,sys; d=json.load(sys.stdin); print(repr(d["sah_cost"]), d["nodes"], d["valid"])')"
done; done
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2"
for climb in 4 12; do
  TREELET_SPLITS=0.3 TREELET_REINSERT=4 TREELET_REINSERT_CLIMB=$climb timeout 150 $T bench rays --suite --accels trbvh,hploc $c --json $OUT/climb_$climb.json > $OUT/climb_$climb.log 2>&1
  echo "climb $climb: $?"; grep -A26 "scene    view" $OUT/climb_$climb.log | grep inside
done
nvidia-smi --query-gpu=clocks.sm --format=csv
cd $OUT && tar czf climb.tgz climb_* && rm climb_*
