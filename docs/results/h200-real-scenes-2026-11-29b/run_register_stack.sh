#!/usr/bin/env bash
# A/B: the walk's top two stack entries in registers (new) against all in local memory (prev); suite (TRBVH bvh2, splits 0.3), instances.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv,noheader
xz -dc .dev/carry/treelet_prev.xz > /tmp/t_prev; xz -dc .dev/carry/treelet.xz > /tmp/t_new; chmod +x /tmp/t_*
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply > /dev/null
for round in 1 2; do for v in prev new; do
  echo "=== $v round $round"
  TREELET_SPLITS=0.3 /tmp/t_$v bench rays --suite --accels trbvh --layouts bvh2 --width 1920 --height 1080 --repeats 5 --json $OUT/ab_${v}_$round.json 2>&1 | grep -E "outside|inside"
  /tmp/t_$v bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 5 2>&1 | grep -E "mesh alone|copy in place|1024 copies|above"
done; done
nvidia-smi --query-gpu=clocks.sm --format=csv,noheader
