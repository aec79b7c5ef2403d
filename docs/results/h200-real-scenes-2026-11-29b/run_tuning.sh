#!/usr/bin/env bash
# Tuning on the suite (Treelet alone, bvh2): split budgets, treelet settings (rounds, gamma, max leaf).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2"
for cfg in "0.3 3,3,8 trbvh,hploc" "0.6 3,3,8 trbvh,hploc" "1.0 3,3,8 trbvh,hploc" "0.3 3,3,4 trbvh,hploc" "0.3 3,3,16 trbvh,hploc" "0.3 2,7,8 trbvh" "0.3 1,7,8 trbvh"; do
  set -- $cfg
  TREELET_SPLITS=$1 TREELET_TREELETS=$2 timeout 120 /tmp/treelet bench rays --suite --accels $3 $c --json $OUT/tune_${1}_${2//,/-}.json > /dev/null 2>&1
  echo "$cfg done"
done
