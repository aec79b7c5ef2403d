#!/usr/bin/env bash
# Split budgets on the suite with the shipped defaults (TRBVH + 2 reinsertion iterations on GPUs), OptiX beside once;
# scans (a subdivided bunny, terrain) to check that splitting leaves them alone.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
T=/tmp/treelet
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2"
PYTHONPATH=/tmp/site timeout 260 $T bench rays --suite --with-optix --accels trbvh,hploc $c --json $OUT/s0_optix.json > $OUT/s0_optix.log 2>&1
echo "splits 0 with OptiX: $?"; grep -A30 "scene    view" $OUT/s0_optix.log
for s in 0.3 0.6 1.0; do
  TREELET_SPLITS=$s timeout 100 $T bench rays --suite --accels trbvh,hploc $c --json $OUT/s$s.json > $OUT/s$s.log 2>&1
  echo "splits $s: $?"; grep -A30 "scene    view" $OUT/s$s.log | grep -E "trbvh|hploc"
done
xz -dc .dev/carry/bunny.obj.xz > /tmp/bunny.obj
python3 peers/meshes/subdivide.py /tmp/bunny.obj 2 /tmp/bunny2.ply > /dev/null 2>&1 || echo "subdivide failed"
for scene in /tmp/bunny2.ply terrain:1000000; do
  for s in 0 0.3 0.6 1.0; do
    echo "== $scene splits $s"
    TREELET_SPLITS=$s $T bench rays --scene $scene --mesh-only --accels trbvh,hploc $c 2>&1 | grep -E "^ +(trbvh|hploc) "
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
cd $OUT && tar czf run1.tgz s*.json s*.log && rm -f s*.json s*.log
