#!/bin/bash
# One H100 lease: error against time for smallpt's estimator and next-event estimation, cornell and the disk-lit room.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
xz -dkf .run/treelet.xz; chmod +x .run/treelet
T=.run/treelet; L=$OUT/log.txt; R="--width 1024 --height 768"; O=/tmp/o; mkdir -p $O
nvidia-smi --query-gpu=name,driver_version --format=csv | tee $L
$T render $R --spp 16 --out /tmp/w.png 2>&1 | grep -v XDG | tail -1 | tee -a $L
for s in cornell scenes/room_disk.json; do
  n=$(basename $s .json)
  echo "== reference $n: nee 8192 spp" | tee -a $L
  $T render --scene $s $R --spp 8192 --integrator nee --seed 99 --out /tmp/ref_$n.exr --report $O/ref_$n.json 2>&1 | grep -v XDG | tail -1 | tee -a $L
  for i in smallpt nee; do
    echo "== $n $i 1024 spp against the reference" | tee -a $L
    $T render --scene $s $R --spp 1024 --integrator $i --reference /tmp/ref_$n.exr --out $O/${n}_$i.png --report $O/${n}_$i.json 2>&1 | grep -v XDG | tail -1 | tee -a $L
    python3 -c "import json; d=json.load(open('$O/${n}_$i.json')); print('render_ms', round(d['render_ms'],1), 'total_s', round(d['total_s'],3)); [print(r['spp'], round(r['elapsed_s'],3), round(r['rmse'],5)) for r in d['rows']]" | tee -a $L
  done
done
tar czf $OUT/results.tgz -C $O .
