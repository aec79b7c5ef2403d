#!/usr/bin/env bash
# M (cwbvh children written out, main b89c6ec) against N (the same, with each plane one fused multiply-add: wip/cwbvh-unroll-fma); N's GPU tests.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_m.xz > /tmp/M; xz -dc .dev/carry/treelet_n.xz > /tmp/N; chmod +x /tmp/M /tmp/N
c="--width 1920 --height 1080 --repeats 5"
for r in M1 N1 N2 M2; do
  s=$(date +%s)
  timeout 60 /tmp/${r:0:1} bench rays --suite --accels trbvh --layouts bvh2,cwbvh $c --json $OUT/$r.json > /tmp/$r.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"
done
export CI=true
for t in layouts tracer instances; do
  xz -dc .dev/carry/tn_$t.xz > /tmp/t_$t; chmod +x /tmp/t_$t
  timeout 100 /tmp/t_$t 2>&1 | grep -E "^test |test result|panicked|seed" | head -40
done
nvidia-smi --query-gpu=clocks.sm --format=csv
