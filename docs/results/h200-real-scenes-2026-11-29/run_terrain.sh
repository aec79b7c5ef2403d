#!/usr/bin/env bash
# Uniform triangles (terrain:N, a height field, as a stand-in for scans) with and without splits.
set -x
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
set +x
for n in 1000000 4000000; do for sp in 0 0.3; do
  echo "=== terrain:$n mesh-only: splits $sp"
  TREELET_SPLITS=$sp /tmp/treelet bench rays --scene terrain:$n --mesh-only --accels lbvh,hploc,trbvh --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | grep -E "^ *(lbvh|hploc|trbvh)"
done; done
nvidia-smi --query-gpu=clocks.sm --format=csv
