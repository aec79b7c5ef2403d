#!/usr/bin/env bash
# bvh4 (4-wide full-precision nodes from bvh2's) against bvh2 and cwbvh, with the new default splits (0.3),
# the suite with OptiX beside; scans; registers of the cast kernels.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
T=/tmp/treelet
c="--width 1920 --height 1080 --repeats 5"
PYTHONPATH=/tmp/site timeout 300 $T bench rays --suite --with-optix --accels trbvh,hploc --layouts bvh2,bvh4 $c --json $OUT/greedy_optix.json > $OUT/greedy_optix.log 2>&1
echo "suite with OptiX: $?"; grep -A40 "scene    view" $OUT/greedy_optix.log
xz -dc .dev/carry/bunny.obj.xz > /tmp/bunny.obj
python3 peers/meshes/subdivide.py /tmp/bunny.obj 2 /tmp/bunny2.ply > /dev/null 2>&1 || echo "subdivide failed"
for scene in /tmp/bunny2.ply terrain:1000000; do
  echo "== $scene"
  $T bench rays --scene $scene --mesh-only --accels trbvh,hploc --layouts bvh2,bvh4 $c 2>&1 | grep -E "^ +(trbvh|hploc) "
done
$T render --scene scenes/real/staircase.ply.xz --help > /dev/null 2>&1
nvidia-smi --query-gpu=clocks.sm --format=csv
cd $OUT && tar czf run3.tgz greedy_* && rm -f greedy_*
