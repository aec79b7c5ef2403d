#!/usr/bin/env bash
# The real-scene suite with OptiX beside (splits 0.3), then without splits (Treelet alone).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
export PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1
c="--width 1920 --height 1080 --repeats 5 --accels lbvh,hploc,trbvh --layouts bvh2,cwbvh"
TREELET_SPLITS=0.3 /tmp/treelet bench rays --suite --with-optix $c --json $OUT/suite_s03.json 2>&1 | grep -v "layout of the\|^loading\|triangles$"
TREELET_SPLITS=0 timeout 200 /tmp/treelet bench rays --suite $c --json $OUT/suite_s0.json 2>&1 | grep -v "layout of the\|^loading\|triangles$"
nvidia-smi --query-gpu=clocks.sm --format=csv
