#!/bin/bash
# Path regeneration (one loop over every ray of a pixel's paths) against the per-sample loop
# (treelet_rr: commit 5bdc0e8); cornell and the disk-lit room, both integrators.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
for f in .run/*.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv | tee $L
export TREELET_PIPELINE_CACHE=/tmp/plc
for T in rr regen; do for s in cornell scenes/room_disk.json; do for i in nee smallpt; do
  .run/treelet_$T render --scene $s --integrator $i --width 64 --height 48 --spp 4 --out /tmp/w.png >/dev/null 2>&1; done; done; done
for k in 1 2; do
for s in cornell scenes/room_disk.json; do for i in nee smallpt; do for T in rr regen; do
  echo -n "$T: " | tee -a $L; .run/treelet_$T render --scene $s --integrator $i --width 1024 --height 768 --spp 1024 --out /tmp/x_$T.exr 2>&1 | grep -v XDG | tail -1 | tee -a $L
done; cmp /tmp/x_rr.exr /tmp/x_regen.exr && echo "  same image" | tee -a $L; done; done
for i in nee smallpt; do for T in rr regen; do
  echo -n "$T: " | tee -a $L; .run/treelet_$T render --integrator $i --out /tmp/y_$T.exr 2>&1 | grep -v XDG | tail -1 | tee -a $L
done; cmp /tmp/y_rr.exr /tmp/y_regen.exr && echo "  same image" | tee -a $L; done
done
