#!/usr/bin/env bash
# Render kernels through bvh2 and bvh4 (TRBVH), and what the layout pilot picks at 256 spp.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
T=/tmp/treelet
for scene in terrain:1000000 city:300000 scenes/room_disk.json; do
  for layout in bvh2 bvh4; do
    for k in 1 2; do
      $T render --scene $scene --accel trbvh --layout $layout --width 1024 --height 768 --spp 64 --integrator nee --out /tmp/x.png --report /tmp/r.json 2>&1 | grep -E "M camera paths" | sed -e "s/^/$layout /" | cut -c1-260
    done
  done
  $T render --scene $scene --accel trbvh --width 1024 --height 768 --spp 256 --integrator nee --explain --out /tmp/x.png 2>&1 | grep -E "layout +|M camera paths" | cut -c1-300
done
nvidia-smi --query-gpu=clocks.sm --format=csv
