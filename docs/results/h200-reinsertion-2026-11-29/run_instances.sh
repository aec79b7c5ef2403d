#!/usr/bin/env bash
# 1 024 turned copies of the 940k bunny with the defaults of f950f92 (TRBVH + 2 reinsertion iterations on GPUs): Treelet and OptiX, one call.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
for round in 1; do
  echo "== treelet bench instances bunny4 32x32, round $round"
  /tmp/treelet bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000,100000 --repeats 7 --json $OUT/instances_bunny4_$round.json 2>&1 | grep -v "^\s*$" | tail -8
  echo "== OptiX instances bunny4 32x32, round $round"
  (cd peers/mitsuba && PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1 python3 instances.py /tmp/bunny4.ply 32 1920 1080 7 2>&1 | tail -6)
done
nvidia-smi --query-gpu=clocks.sm --format=csv
