#!/bin/bash
# Wall time against kernel time of the README's render, each integrator, three runs each.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
xz -dkf .run/treelet.xz; chmod +x .run/treelet
T=.run/treelet; L=$OUT/log.txt
echo "HOME=$HOME; nvidia cache: $(ls -d ~/.cache/nvidia 2>/dev/null)" | tee -a $L
for i in nee smallpt nee smallpt nee smallpt; do
  /usr/bin/time -f "process wall %e s" $T render --width 1024 --height 768 --spp 1024 --integrator $i --out /tmp/x.png 2>&1 | grep -v XDG | tee -a $L
done
/usr/bin/time -f "process wall %e s" $T render --width 8 --height 8 --spp 4 --out /tmp/y.png 2>&1 | grep -v XDG | tee -a $L
echo "nvidia cache after: $(du -sh ~/.cache/nvidia 2>/dev/null)" | tee -a $L
