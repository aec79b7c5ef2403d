#!/usr/bin/env bash
# An experiment on the instanced walk's own cost: the instance of the hit settled on leaving a
# mesh (the hit on entering kept at the stack's end) instead of a compare every step.
# `bench instances` on 1 024 turned copies of the 940k bunny: b69e0d5's walk (old) and the variant
# (new) alternately, three rounds (.dev/carry/bins.tar.xz: bins/old, bins/new, stripped).
# Carry: .gl, .dev/carry/bins.tar.xz, .dev/carry/bunny.obj.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
tar xJf .dev/carry/bins.tar.xz -C /tmp && cp /tmp/bins/old /tmp/bins/new /tmp/ && chmod +x /tmp/old /tmp/new
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply
for round in 1 2 3; do
  for b in old new; do
    echo "== $b, round $round"
    timeout 100 /tmp/$b bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 7 --json $OUT/instances_${b}_$round.json 2>&1 | grep -E "mesh alone|in place|copies|above"
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
