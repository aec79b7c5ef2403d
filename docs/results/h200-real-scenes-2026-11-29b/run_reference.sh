#!/usr/bin/env bash
# Tree quality against trace speed: the quality reference (obvhs PLOC + full reinsertion, CPU) and the sweep beside TRBVH, no splits, bvh2.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/treelet_peers.xz > /tmp/treelet; chmod +x /tmp/treelet
TREELET_SPLITS=0 timeout 500 /tmp/treelet bench rays --suite --accels trbvh,reference,sweep --layouts bvh2 --width 1920 --height 1080 --repeats 5 --json $OUT/reference.json 2>&1 | grep -v "layout of the\|^loading\|triangles$"
