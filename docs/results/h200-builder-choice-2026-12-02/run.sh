#!/usr/bin/env bash
# The builder choice (issue 63, item 5) measured on the real-scene suite: LBVH, H-PLOC and TRBVH,
# each laid out as bvh2 and cwbvh, build and primary/diffuse rays, at 1920x1080 (binary of d349d6c).
# Carry: .gl (the Vulkan loader's debs), .dev/carry/treelet.xz (the stripped release binary).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/T; chmod +x /tmp/T
timeout 400 /tmp/T bench rays --suite --accels lbvh,hploc,trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5 --json $OUT/suite.json > $OUT/suite.log 2>&1
echo "rc=$?"; tail -60 $OUT/suite.log
nvidia-smi --query-gpu=clocks.sm --format=csv
