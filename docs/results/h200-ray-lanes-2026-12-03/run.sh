#!/usr/bin/env bash
# Diffuse rays on a fixed number of lanes, each taking every N-th ray in one
# walk loop (TREELET_RAY_LANES=N), against one lane a ray (N=0), alternately
# in one call, on the real-scene suite (binary N: main at this commit).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_n.xz > /tmp/N; chmod +x /tmp/N
xz -dc .dev/carry/ps.xz > /tmp/ps; chmod +x /tmp/ps
timeout 60 /tmp/N bench rays --scene terrain:10000 --mesh-only --accels trbvh --layouts bvh2,cwbvh --width 256 --height 256 --repeats 1 > $OUT/quick.log 2>&1; echo "quick rc=$?"; tail -3 $OUT/quick.log
timeout 60 /tmp/ps render::cast_bvh2_triangles_cs render::cast_cwbvh_triangles_cs render::cast_instances_cs > $OUT/ps.log 2>&1; echo "ps rc=$?"; cat $OUT/ps.log | tail -6
c="--suite --accels trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5"
for r in N:0:1 N:131072:1 N:262144:1 N:524288:1 N:0:2; do
  IFS=: read bin lanes k <<< "$r"
  s=$(date +%s)
  TREELET_RAY_LANES=$lanes timeout 100 /tmp/$bin bench rays $c --json $OUT/${bin}_${lanes}_$k.json > $OUT/${bin}_${lanes}_$k.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"
done
# OptiX (Mitsuba 3, peers/mitsuba/rays.py) beside, one more run of the suite on 262144 lanes.
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
s=$(date +%s)
PYTHONPATH=/tmp/site TREELET_RAY_LANES=262144 timeout 200 /tmp/N bench rays $c --with-optix --json $OUT/optix.json > $OUT/optix.log 2>&1
echo "optix rc=$? $(( $(date +%s) - s ))s"
nvidia-smi --query-gpu=clocks.sm --format=csv
