#!/usr/bin/env bash
# Renders with this build (the stack fix), the commands of docs/results/h200-path-registers-2026-11-28/run.sh.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv,noheader
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
R="--width 1024 --height 768 --device gpu --spp 1024"
/tmp/treelet render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
for i in 1 2 3; do
  echo "== round $i"
  timeout -s KILL 60 /tmp/treelet render $R --out /tmp/c.pfm 2>&1 | tail -1
  timeout -s KILL 60 /tmp/treelet render --scene scenes/room_disk.json $R --out /tmp/r.pfm 2>&1 | tail -1
  timeout -s KILL 60 /tmp/treelet render --scene .dev/carry/bunny.obj --width 1024 --height 768 --device gpu --spp 256 --out /tmp/b.pfm 2>&1 | tail -1
done
nvidia-smi --query-gpu=clocks.sm --format=csv,noheader
