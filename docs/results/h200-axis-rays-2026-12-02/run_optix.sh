#!/usr/bin/env bash
# G with OptiX (Mitsuba 3) beside it, the suite's table.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_k.xz > /tmp/G; chmod +x /tmp/G
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
PYTHONPATH=/tmp/site timeout 200 /tmp/G bench rays --suite --with-optix --accels trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5 --json $OUT/optix.json 2>&1 | grep -v "^loading" | tail -32
nvidia-smi --query-gpu=clocks.sm --format=csv
