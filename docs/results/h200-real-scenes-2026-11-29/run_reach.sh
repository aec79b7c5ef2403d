#!/usr/bin/env bash
# Split budgets inside the interiors (trbvh and hploc, bvh2), and the per-ray floor of the cast kernel.
set -x
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
mkdir -p /tmp/s $OUT/j
T=/tmp/treelet
common="--width 1920 --height 1080 --repeats 5"
set +x
for name in sponza_dabrovic classroom living_room breakfast_room staircase; do
  xz -dc .dev/carry/scenes/$name.ply.xz > /tmp/s/$name.ply
  cam=$(python3 -c "import json; m=[m for m in json.load(open('.dev/carry/scenes/MANIFEST.json'))['models'] if m['name']=='$name'][0]['camera']; print(','.join(str(x) for x in m['eye']+m['look_at']))")
  for sp in 0 0.3 1; do
    echo "=== $name inside: splits $sp"
    TREELET_SPLITS=$sp $T bench rays --scene /tmp/s/$name.ply --mesh-only --camera $cam --accels hploc,trbvh --layouts bvh2 $common --json $OUT/j/b_${name}_$sp.json 2>&1 | grep -E "^ *(hploc|trbvh)"
  done
done
for CITY in 300000 1000000; do
for sp in 0 0.3 1; do
  echo "=== city $CITY outside: splits $sp"
  TREELET_SPLITS=$sp $T bench rays --scene city:$CITY --mesh-only --accels hploc,trbvh --layouts bvh2 $common --json $OUT/j/b_city_${CITY}_$sp.json 2>&1 | grep -E "^ *(hploc|trbvh)"
done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
(cd $OUT && tar cJf results5.tar.xz j && rm -rf j)
