#!/usr/bin/env bash
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export CI=true
xz -dc .dev/carry/t_layouts.xz > /tmp/layouts; chmod +x /tmp/layouts
/tmp/layouts 2>&1 | grep -E "^test |test result|panicked|seed" | head -30
xz -dc .dev/carry/treelet_a.xz > /tmp/A; xz -dc .dev/carry/treelet_e.xz > /tmp/E; chmod +x /tmp/A /tmp/E
c="--width 1920 --height 1080 --repeats 3"
for r in A E A E; do echo "== $r"; timeout 60 /tmp/$r bench rays --suite --accels trbvh --layouts bvh2 $c 2>&1 | grep -E "^ +(breakfast|classroom|staircase|city)" | awk '{print $1, $2, $6, $7, $8}' | head -12; done
