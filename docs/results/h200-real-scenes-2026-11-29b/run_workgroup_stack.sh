#!/usr/bin/env bash
# cwbvh: private stack against the top 8 entries in workgroup memory, on the suite (splits 0.3), after the stack fix.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
TREELET_SPLITS=0.3 /tmp/treelet bench rays --suite --accels trbvh --layouts bvh2,cwbvh --workgroup-stack --width 1920 --height 1080 --repeats 5 --json $OUT/wg.json 2>&1 | grep -v "layout of the\|^loading\|triangles$"
