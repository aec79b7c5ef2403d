#!/usr/bin/env bash
# Reinsertion of internal nodes only (TREELET_REINSERT_LEAVES=0) against all nodes, 4 iterations, splits 0.3.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
T=/tmp/treelet
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2"
for leaves in 0 1; do
  TREELET_SPLITS=0.3 TREELET_REINSERT=4 TREELET_REINSERT_LEAVES=$leaves timeout 150 $T bench rays --suite --accels trbvh,hploc $c --json $OUT/leaves_$leaves.json > $OUT/leaves_$leaves.log 2>&1
  echo "leaves $leaves: $?"; grep -A26 "scene    view" $OUT/leaves_$leaves.log | grep -v "^\s*scene\|^rates"
done
nvidia-smi --query-gpu=clocks.sm --format=csv
cd $OUT && tar czf leaves.tgz leaves_* && rm leaves_*
