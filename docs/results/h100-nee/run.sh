#!/bin/bash
# One H100 lease, the final binary (--accel auto: the room gets the treelet BVH): error against wall time on cornell and scenes/room_disk.json for
# Treelet's two integrators (RMSE against a Treelet reference of 8192 spp) and Mitsuba 3 on the room
# (RMSE against Treelet's reference, and against Mitsuba's own 4096-spp image).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
xz -dkf .run/treelet.xz; chmod +x .run/treelet
T=.run/treelet; L=$OUT/log.txt; R="--width 1024 --height 768"; O=/tmp/o; mkdir -p $O /tmp/m
nvidia-smi --query-gpu=name,driver_version --format=csv | tee $L
python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]"
(PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 200 python3 -c "import mitsuba" ) &
for s in cornell scenes/room_disk.json; do
  n=$(basename $s .json)
  $T render --scene $s $R --spp 16 --out /tmp/w.png > /dev/null 2>&1
  echo "== $n reference: treelet render --scene $s $R --spp 8192 --integrator nee --seed 99" | tee -a $L
  $T render --scene $s $R --spp 8192 --integrator nee --seed 99 --out /tmp/ref_$n.exr 2>&1 | grep -v XDG | tail -1 | tee -a $L
  for i in smallpt nee; do
    echo "== treelet render --scene $s $R --spp 1024 --integrator $i --reference REF --report F" | tee -a $L
    $T render --scene $s $R --spp 1024 --integrator $i --reference /tmp/ref_$n.exr --out $O/${n}_$i.png --report $O/${n}_$i.json 2>&1 | grep -v XDG | tail -1 | tee -a $L
    python3 -c "import json; d=json.load(open('$O/${n}_$i.json')); print('render_ms', round(d['render_ms'],1), 'total_s', round(d['total_s'],3), 'process_s', round(d['process_s'],3)); [print('spp', r['spp'], 'wall_s', round(r['elapsed_s'],3), 'rmse', round(r['rmse'],5)) for r in d['rows']]" | tee -a $L
  done
done
wait
echo "== mitsuba: peers/mitsuba/room_disk.py /tmp/m 16,64,256,1024,4096" | tee -a $L
PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 240 python3 peers/mitsuba/room_disk.py /tmp/m 16,64,256,1024,4096 2>&1 | grep '^{' | tee $O/mitsuba.jsonl | tee -a $L
echo "== treelet compare MITSUBA_N --reference TREELET_REF, then --reference MITSUBA_4096" | tee -a $L
for n in 16 64 256 1024 4096; do $T compare /tmp/m/mitsuba_room_disk_${n}spp.exr --reference /tmp/ref_room_disk.exr 2>&1 | grep -v XDG | tee -a $L; done
for n in 16 64 256 1024; do $T compare /tmp/m/mitsuba_room_disk_${n}spp.exr --reference /tmp/m/mitsuba_room_disk_4096spp.exr 2>&1 | grep -v XDG | tee -a $L; done
tar czf $OUT/results.tgz -C $O .
