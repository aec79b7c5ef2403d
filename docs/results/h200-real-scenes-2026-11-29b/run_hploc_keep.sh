#!/usr/bin/env bash
# H-PLOC's clusters kept per merged range (TREELET_HPLOC_KEEP; default 2, tuned on a scan) on the suite, splits 0 and 0.3.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
for sp in 0.3 0; do for keep in 2 4 8 16; do
  TREELET_SPLITS=$sp TREELET_HPLOC_KEEP=$keep timeout 100 /tmp/treelet bench rays --suite --accels hploc --layouts bvh2 --width 1920 --height 1080 --repeats 5 --json $OUT/keep_${sp}_$keep.json > /dev/null 2>&1; echo "$sp $keep done"
done; done
cd $OUT && tar czf keep.tgz keep_*.json && rm keep_*.json
