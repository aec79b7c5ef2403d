#!/usr/bin/env bash
# Work per ray over the GPU-built trees (counted on the CPU): the cwbvh of split trees from outside.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/trace_counts.xz > /tmp/tc; chmod +x /tmp/tc
for s in breakfast_room staircase; do
  for dev in gpu cpu; do
    for sp in 0.3 0; do
      echo "== $s device $dev splits $sp"; TREELET_COUNTS_DEVICE=$dev TREELET_SPLITS=$sp /tmp/tc scenes/real/$s.ply.xz 320 180 2>&1 | tail -n 4
    done
  done
done
