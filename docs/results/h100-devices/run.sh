#!/bin/bash
# H100: render --devices (the GPU alone against the GPU plus the CPU runner), and the render tests.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
for f in .run/*.xz .run/tests/*.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
[ -e /work/main ] || { mkdir -p /work; ln -s $PWD /work/main; }
T=.run/treelet; L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv | tee $L
nproc | tee -a $L
$T render --devices list 2>&1 | tee -a $L
echo "== warm-up process (discarded)" | tee -a $L
$T render --width 256 --height 192 --spp 16 --out /tmp/w.png 2>&1 | tail -1 | tee -a $L
for scene in cornell scenes/room_disk.json; do
  A="--scene $scene --width 1024 --height 768 --spp 1024"
  for i in 1 2; do
    echo "== $scene: GPU alone" | tee -a $L
    $T render $A --devices 0 --out /tmp/g.pfm --report $OUT/${scene##*/}_gpu_$i.json 2>&1 | tee -a $L
    echo "== $scene: GPU + CPU runner (--devices all)" | tee -a $L
    $T render $A --devices all --out /tmp/a.pfm --report $OUT/${scene##*/}_all_$i.json 2>&1 | tee -a $L
  done
  echo "== $scene: CPU runner alone, 16 spp" | tee -a $L
  $T render --scene $scene --width 1024 --height 768 --spp 16 --devices cpu --out /tmp/c.pfm 2>&1 | tee -a $L
  $T compare /tmp/a.pfm --reference /tmp/g.pfm | tee -a $L
done
exit 0
for t in devices render variants layouts; do
  (cd /work/main/tests && CI=1 timeout 200 $OLDPWD/.run/tests/$t --test-threads 8 --nocapture 2>&1) | grep -E "^test |test result|panicked|GPU \+ CPU" | tee -a $L
done
