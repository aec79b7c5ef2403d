#!/usr/bin/env bash
# Postponed leaves (B, speculative while-while) against the shipped walk (A).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_a.xz > /tmp/A; xz -dc .dev/carry/treelet_b.xz > /tmp/B; chmod +x /tmp/A /tmp/B
c="--width 1920 --height 1080 --repeats 5"
for r in A1 B1 B2 A2; do
  s=$(date +%s)
  timeout 150 /tmp/${r:0:1} bench rays --suite --accels trbvh --layouts bvh2 $c --json $OUT/$r.json > $OUT/$r.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"; grep -A16 "scene    view" $OUT/$r.log
done
xz -dc .dev/carry/bunny.obj.xz > /tmp/bunny.obj
python3 peers/meshes/subdivide.py /tmp/bunny.obj 2 /tmp/bunny2.ply > /dev/null 2>&1 || echo "subdivide failed"
for T in A B A B; do
  echo "== $T bunny2 / terrain"
  for scene in /tmp/bunny2.ply terrain:1000000; do timeout 40 /tmp/$T bench rays --scene $scene --mesh-only --accels trbvh --layouts bvh2 $c 2>&1 | grep -E "^ +trbvh "; done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
