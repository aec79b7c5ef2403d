#!/bin/bash
# Variants of where a black surface ends a path: before (none), treelet (always), a (only NEE's
# roulette), b (NEE only); cornell and the disk-lit room, both integrators, 1024x768, 1024 spp.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
for f in .run/*.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
L=$OUT/log.txt
export TREELET_PIPELINE_CACHE=/tmp/plc
B="before treelet a b"
for T in $B; do for s in cornell scenes/room_disk.json; do for i in nee smallpt; do
  .run/treelet_${T#treelet} render --scene $s --integrator $i --width 64 --height 48 --spp 4 --out /tmp/w.png >/dev/null 2>&1 || .run/treelet render --scene $s --integrator $i --width 64 --height 48 --spp 4 --out /tmp/w.png >/dev/null 2>&1; done; done; done
for k in 1 2; do for s in cornell scenes/room_disk.json; do for i in smallpt nee; do for T in before a b treelet; do
  X=.run/treelet_$T; [ $T = treelet ] && X=.run/treelet
  echo -n "$T: " | tee -a $L; $X render --scene $s --integrator $i --width 1024 --height 768 --spp 1024 --out /tmp/x.png 2>&1 | grep -v XDG | tail -1 | grep -oE "^[^ ]+|integrator [a-z]+|kernels [0-9.]+ s" | tr '\n' ' ' | tee -a $L; echo | tee -a $L
done; done; done; done
