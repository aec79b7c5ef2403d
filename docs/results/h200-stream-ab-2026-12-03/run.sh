#!/usr/bin/env bash
# C (c93f0fd: walks of one ray, before ray lanes) against N (main: every walk a stream, one ray by
# default), alternately in one call on the real-scene suite; then the engine API's GPU tests and
# `bench dynamic`, which the cast crash had stopped on NVIDIA.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
for b in n c; do xz -dc .dev/carry/treelet_$b.xz > /tmp/$b; chmod +x /tmp/$b; done
c="--suite --accels trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5"
for r in c1 n1 n2 c2; do
  s=$(date +%s)
  timeout 100 /tmp/${r:0:1} bench rays $c --json $OUT/$r.json > /tmp/$r.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"
done
export CI=true
for t in tracer render; do
  xz -dc .dev/carry/t_$t.xz > /tmp/t_$t; chmod +x /tmp/t_$t
  timeout 200 /tmp/t_$t 2>&1 | grep -E "^test |test result|panicked|seed|GPU|adapter" | head -40 > /tmp/t_$t.txt
  echo "== $t"; grep "test result" /tmp/t_$t.txt
done
cat /tmp/t_*.txt > $OUT/tests.txt
timeout 120 /tmp/n bench dynamic --frames 20 --device gpu --json $OUT/dynamic.json > /tmp/dynamic.log 2>&1; echo "dynamic rc=$?"; tail -12 /tmp/dynamic.log
tail -40 /tmp/dynamic.log > $OUT/dynamic.log
nvidia-smi --query-gpu=clocks.sm --format=csv
