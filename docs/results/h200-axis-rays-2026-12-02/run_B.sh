#!/usr/bin/env bash
# The shipped walk (A, main before this change) against the walk with parallel
# axes bounded by the root and ties reached (B), then B's GPU tests.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_e.xz > /tmp/A; xz -dc .dev/carry/treelet_f.xz > /tmp/B; chmod +x /tmp/A /tmp/B
c="--width 1920 --height 1080 --repeats 5"
for r in A1 B1 B2 A2; do
  s=$(date +%s)
  timeout 80 /tmp/${r:0:1} bench rays --suite --accels trbvh --layouts bvh2,cwbvh $c --json $OUT/$r.json > $OUT/$r.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"; grep -A30 "scene    view" $OUT/$r.log | head -40
done
export CI=true
for t in layouts tracer instances; do
  xz -dc .dev/carry/t_$t.xz > /tmp/t_$t; chmod +x /tmp/t_$t
  timeout 80 /tmp/t_$t 2>&1 | grep -E "^test |test result|panicked|seed" | head -40
done
nvidia-smi --query-gpu=clocks.sm --format=csv
