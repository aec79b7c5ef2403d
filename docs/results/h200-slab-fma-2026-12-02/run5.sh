#!/usr/bin/env bash
# Slab test in FMA form (B) against the shipped one (A); cwbvh anomaly on the breakfast room from outside.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/A; xz -dc .dev/carry/treelet_b.xz > /tmp/B; chmod +x /tmp/A /tmp/B
# no OptiX this call (carry limit)
c="--width 1920 --height 1080 --repeats 5"
timeout 300 /tmp/A bench rays --suite --accels trbvh --layouts bvh2 $c --json $OUT/A1.json > $OUT/A1.log 2>&1
echo "A1 $?"; grep -A30 "scene    view" $OUT/A1.log
for r in B1 A2 B2; do
  timeout 200 /tmp/${r:0:1} bench rays --suite --accels trbvh --layouts bvh2 $c --json $OUT/$r.json > $OUT/$r.log 2>&1
  echo "$r $?"; grep -A16 "scene    view" $OUT/$r.log
done
xz -dc .dev/carry/bunny.obj.xz > /tmp/bunny.obj
python3 peers/meshes/subdivide.py /tmp/bunny.obj 2 /tmp/bunny2.ply > /dev/null 2>&1 || echo "subdivide failed"
for T in A B A B; do
  echo "== $T bunny2 / terrain"
  for scene in /tmp/bunny2.ply terrain:1000000; do /tmp/$T bench rays --scene $scene --mesh-only --accels trbvh --layouts bvh2 $c 2>&1 | grep -E "^ +trbvh "; done
done
echo "== cwbvh anomaly: breakfast outside"
for env in "X=1" "TREELET_SPLITS=0" "TREELET_REINSERT=0" "TREELET_SPLITS=0 TREELET_REINSERT=0"; do
  echo "-- $env"
  env $env /tmp/A bench rays --scene scenes/real/breakfast_room.ply.xz --mesh-only --accels trbvh,lbvh,hploc --layouts bvh2,cwbvh $c 2>&1 | grep -E "^ +(trbvh|lbvh|hploc) "
done
nvidia-smi --query-gpu=clocks.sm --format=csv
