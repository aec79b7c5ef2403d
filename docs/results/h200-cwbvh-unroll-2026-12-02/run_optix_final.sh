#!/usr/bin/env bash
# Main (9c26003: cwbvh children written out, wide prim cost 0.6) with OptiX (Mitsuba 3) beside it: the suite's table, TRBVH and H-PLOC.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_p.xz > /tmp/O; chmod +x /tmp/O
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
PYTHONPATH=/tmp/site timeout 300 /tmp/O bench rays --suite --with-optix --accels trbvh,hploc --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5 --json $OUT/optix.json > /tmp/optix.log 2>&1; echo rc=$?
grep -v "^loading" /tmp/optix.log | tail -60
nvidia-smi --query-gpu=clocks.sm --format=csv
