#!/usr/bin/env bash
# Reinsertion on scans and uniform meshes (must keep their lead), and 2 iterations with a climb bound of 12 on the suite.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
T=/tmp/treelet
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply > /dev/null 2>&1 || echo "subdivide failed"
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2"
for scene in /tmp/bunny4.ply terrain:1000000; do
  for cfg in "0 0" "4 0" "2 12"; do set -- $cfg
    echo "== $scene reinsert $1 climb $2"
    TREELET_REINSERT=$1 TREELET_REINSERT_CLIMB=$2 $T bench rays --scene $scene --mesh-only --accels trbvh,hploc $c 2>&1 | grep -E "^ +(trbvh|hploc) "
  done
done
TREELET_SPLITS=0.3 TREELET_REINSERT=2 TREELET_REINSERT_CLIMB=12 timeout 150 $T bench rays --suite --accels trbvh,hploc $c --json $OUT/r2c12.json > $OUT/r2c12.log 2>&1
echo "suite r2 c12: $?"; grep -A26 "scene    view" $OUT/r2c12.log | grep inside
nvidia-smi --query-gpu=clocks.sm --format=csv
