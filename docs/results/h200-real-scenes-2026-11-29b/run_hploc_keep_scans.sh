#!/usr/bin/env bash
# H-PLOC keep 2 against 4 on scans and uniform meshes (bunny4 940k, terrain 1M), mesh-only, no splits.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply > /dev/null
for round in 1 2; do for keep in 2 4; do for s in /tmp/bunny4.ply terrain:1000000; do
  echo "keep $keep $s"; TREELET_HPLOC_KEEP=$keep /tmp/treelet bench rays --scene $s --mesh-only --accels hploc --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | grep -E "^ *hploc"
done; done; done
