#!/usr/bin/env bash
# A/B: the traversal stack zero-filled (old) against left undefined (new), same scenes and rays.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_old.xz > /tmp/t_old; xz -dc .dev/carry/treelet.xz > /tmp/t_new; chmod +x /tmp/t_*
mkdir -p /tmp/s; xz -dc .dev/carry/scenes/classroom.ply.xz > /tmp/s/classroom.ply
cam=$(python3 -c "import json; m=[m for m in json.load(open('.dev/carry/scenes/MANIFEST.json'))['models'] if m['name']=='classroom'][0]['camera']; print(','.join(str(x) for x in m['eye']+m['look_at']))")
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2,cwbvh"
for round in 1 2; do for v in old new; do
  echo "=== $v terrain:2"; /tmp/t_$v bench rays --scene terrain:2 --mesh-only --accels lbvh $c 2>&1 | grep -E "^ *(lbvh|hploc|trbvh)|rays/s"
  echo "=== $v terrain:1000000"; /tmp/t_$v bench rays --scene terrain:1000000 --mesh-only --accels trbvh $c 2>&1 | grep -E "^ *(lbvh|hploc|trbvh)"
  echo "=== $v classroom outside"; TREELET_SPLITS=0.3 /tmp/t_$v bench rays --scene /tmp/s/classroom.ply --mesh-only --accels trbvh $c 2>&1 | grep -E "^ *(lbvh|hploc|trbvh)"
  echo "=== $v classroom inside"; TREELET_SPLITS=0.3 /tmp/t_$v bench rays --scene /tmp/s/classroom.ply --mesh-only --camera $cam --accels trbvh $c 2>&1 | grep -E "^ *(lbvh|hploc|trbvh)"
done; done
nvidia-smi --query-gpu=clocks.sm --format=csv
