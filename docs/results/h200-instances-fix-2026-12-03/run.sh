#!/usr/bin/env bash
# The instanced grid's primary-ray regression fixed (slab tests widen far distances by 1 + 2^-19
# again, not by the ties' 1 + 2^-14): `bench instances` on 1 024 turned copies of the 940k bunny with
# 337439a (old) and the fix (new) alternately (.dev/carry/bins.tar.xz: bins/old, bins/new, stripped), and OptiX's
# instances (peers/mitsuba/instances.py; the Mitsuba site of .whl/site.tar.xz now keeps the
# `shapegroup`, `instance` and `merge` plugins), twice; then the suite against OptiX with the fix
# and, for the change, without OptiX with 337439a.
# Carry: .gl, .whl, .dev/carry/bins.tar.xz, .dev/carry/bunny.obj.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
tar xJf .dev/carry/bins.tar.xz -C /tmp && cp /tmp/bins/old /tmp/bins/new /tmp/ && chmod +x /tmp/old /tmp/new
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
for round in 1 2; do
  for b in old new; do
    echo "== $b: treelet bench instances bunny4 32x32, round $round"
    timeout 100 /tmp/$b bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 7 --json $OUT/instances_${b}_$round.json 2>&1 | grep -v "^\s*$" | tail -7
  done
  echo "== OptiX instances bunny4 32x32, round $round"
  (cd peers/mitsuba && PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1 timeout 120 python3 instances.py /tmp/bunny4.ply 32 1920 1080 7 2>&1 | tail -6)
done
nvidia-smi --query-gpu=clocks.sm --format=csv
echo "== new: the suite with OptiX"
PYTHONPATH=/tmp/site timeout 220 /tmp/new bench rays --suite --with-optix --accels trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5 --json $OUT/suite_new.json 2>&1 | grep -v "^loading" | tail -24
echo "== old: the suite"
timeout 150 /tmp/old bench rays --suite --accels trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5 --json $OUT/suite_old.json 2>&1 | grep -v "^loading" | tail -24
nvidia-smi --query-gpu=clocks.sm --format=csv
