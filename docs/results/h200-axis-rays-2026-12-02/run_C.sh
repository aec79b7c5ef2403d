#!/usr/bin/env bash
# The shipped walk (A, main before this change) against the walk with parallel
# axes bounded by the root and ties reached (B); here C, the same with the widening of ties folded into the slab test.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_e.xz > /tmp/A; xz -dc .dev/carry/treelet_g.xz > /tmp/C; chmod +x /tmp/A /tmp/C
c="--width 1920 --height 1080 --repeats 5"
for r in A1 C1 C2 A2; do
  s=$(date +%s)
  timeout 80 /tmp/${r:0:1} bench rays --suite --accels trbvh --layouts bvh2,cwbvh $c --json $OUT/$r.json > $OUT/$r.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"; grep -A30 "scene    view" $OUT/$r.log | head -40
done
nvidia-smi --query-gpu=clocks.sm --format=csv
