#!/usr/bin/env bash
# The slab test as one fused multiply-add a plane, made conservative (issue 63): main at 01bdc6d
# (old) against the change (new), alternated, on the real-scene suite (TRBVH, `bvh2`), and the GPU
# tests of exact hits (layouts, instances) on the H200's fused FMA.
# Carry: .gl, .dev/carry/bins.tar.xz (pack/old, pack/new, pack/layouts, pack/instances: stripped).
# Usage: run.sh tests|ROUND  (ROUND: 1 runs old then new, 2 new then old)
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
tar xJf .dev/carry/bins.tar.xz -C /tmp
B=/tmp/pack
if [ "$1" = tests ]; then
  # The test binaries read scenes from the path they were built at.
  mkdir -p /work && ln -sfn "$PWD" /work/main
  (cd /tmp && CI=true timeout 200 $B/layouts 2>&1 | grep -E "^test |test result|panicked" | tail -20)
  (cd /tmp && CI=true timeout 120 $B/instances 2>&1 | grep -E "^test |test result|panicked" | tail -12)
  shift
fi
for r in "$@"; do
  order="old new"; [ "$r" = 2 ] && order="new old"
  for b in $order; do
    echo "== $b, round $r"
    timeout 140 $B/$b bench rays --suite --accels trbvh --layouts bvh2 --width 1920 --height 1080 --repeats 5 --json $OUT/suite_${b}_$r.json 2>&1 | grep -v "^loading" | tail -15
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
