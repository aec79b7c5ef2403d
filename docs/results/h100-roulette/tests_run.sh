#!/bin/bash
# GPU = CPU render and devices tests with path regeneration; is a GPU render deterministic?
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
for f in .run/*.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv | tee $L
export TREELET_PIPELINE_CACHE=/tmp/plc
for k in 1 2 3; do .run/treelet_regen render --out /tmp/r$k.exr 2>&1 | grep -v XDG | tail -1 | tee -a $L; done
for k in 1 2; do .run/treelet_regen render --scene scenes/room_disk.json --width 256 --height 192 --spp 64 --out /tmp/m$k.exr 2>&1 | grep -v XDG | tail -1 | tee -a $L; done
cmp /tmp/r1.exr /tmp/r2.exr && cmp /tmp/r1.exr /tmp/r3.exr && echo "cornell: three runs, one image" | tee -a $L
cmp /tmp/m1.exr /tmp/m2.exr && echo "room: two runs, one image" | tee -a $L
[ -e /work/main ] || { mkdir -p /work; ln -s $PWD /work/main; }
for t in render devices; do (cd /work/main/tests && CI=1 timeout 100 /work/main/.run/${t}_test --test-threads 4 2>&1 | grep -E "^test |test result|panicked|seed" | tee -a $L); done
