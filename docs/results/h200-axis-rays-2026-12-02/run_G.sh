#!/usr/bin/env bash
# A (main) against G (what is committed: E's ties, the parallel bound in the
# plain walks only); then G's GPU tests.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_e.xz > /tmp/A; xz -dc .dev/carry/treelet_k.xz > /tmp/G; chmod +x /tmp/A /tmp/G
c="--width 1920 --height 1080 --repeats 5"
for r in A1 G1 G2 A2; do
  s=$(date +%s)
  timeout 60 /tmp/${r:0:1} bench rays --suite --accels trbvh --layouts bvh2,cwbvh $c --json $OUT/$r.json > /tmp/$r.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"
done
export CI=true
for t in layouts tracer instances; do
  xz -dc .dev/carry/t_$t.xz > /tmp/t_$t; chmod +x /tmp/t_$t
  timeout 80 /tmp/t_$t 2>&1 | grep -E "^test |test result|panicked|seed" | head -40
done
nvidia-smi --query-gpu=clocks.sm --format=csv
