#!/bin/bash
# NEE with one traversal call site: the disk-lit room with each accel, cornell at 1024 spp, a mesh in the room.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
xz -dkf .run/treelet.xz; chmod +x .run/treelet
T=.run/treelet; L=$OUT/log.txt; R="--width 1024 --height 768"
$T render $R --spp 4 --out /tmp/w.png 2>&1 | grep -v XDG | tail -1 | tee -a $L
for a in none trbvh; do for i in smallpt nee; do
  $T render --scene scenes/room_disk.json $R --spp 16 --accel $a --integrator $i --out /tmp/a.png > /dev/null 2>&1
  $T render --scene scenes/room_disk.json $R --spp 256 --accel $a --integrator $i --out /tmp/a.png 2>&1 | grep -v XDG | tail -1 | tee -a $L
done; done
for i in smallpt nee; do for r in 1 2; do
  $T render $R --spp 1024 --integrator $i --out /tmp/c.png 2>&1 | grep -v XDG | tail -1 | tee -a $L
done; done
for i in smallpt nee; do
  $T render --scene terrain:100000 $R --spp 64 --integrator $i --out /tmp/t.png > /dev/null 2>&1
  $T render --scene terrain:100000 $R --spp 64 --integrator $i --out /tmp/t.png 2>&1 | grep -v XDG | tail -1 | tee -a $L
done
