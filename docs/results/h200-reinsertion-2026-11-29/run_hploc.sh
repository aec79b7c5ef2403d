#!/usr/bin/env bash
# H-PLOC with 1 iteration of reinsertion (climb 12), no splits: does it lift the large triangles that slow
# H-PLOC's bvh2 primary rays from outside (breakfast room 2.2 G against the TRBVH's 13 G)?
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
T=/tmp/treelet
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2"
for r in 0 1 2; do
  TREELET_REINSERT=$r timeout 150 $T bench rays --suite --accels hploc $c > $OUT/hploc_r$r.log 2>&1
  echo "== hploc reinsert $r: $?"; grep -A14 "scene    view" $OUT/hploc_r$r.log | grep hploc
done
