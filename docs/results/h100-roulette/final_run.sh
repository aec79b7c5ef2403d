#!/bin/bash
# Final code (NEE roulette, path regeneration): wall against kernel time of the README's 1024 spp
# render, then Mitsuba 3's renders of the room and `treelet bench error --mitsuba`, in one call.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
for f in .run/*.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
T=.run/treelet_regen; L=$OUT/log.txt; R=$OUT/res; mkdir -p $R /tmp/mit
nvidia-smi --query-gpu=name,driver_version --format=csv | tee $L
python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]" &
export TREELET_PIPELINE_CACHE=/tmp/plc
for s in cornell scenes/room_disk.json; do for i in nee smallpt; do $T render --scene $s --integrator $i --width 64 --height 48 --spp 4 --out /tmp/w.png >/dev/null 2>&1; done; done
echo "== treelet render --width 1024 --height 768 --spp 1024 (x3 per integrator)" | tee -a $L
for i in nee smallpt; do for k in 1 2 3; do /usr/bin/time -f "  process wall %e s" $T render --width 1024 --height 768 --spp 1024 --integrator $i --explain --out /tmp/x.png 2>&1 | grep -E "start-up|process|cornell" | tee -a $L; done; done
wait
echo "== mitsuba" | tee -a $L
PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 120 python3 peers/mitsuba/room_disk.py /tmp/mit 16,64,256,1024,4096 2>&1 | grep '^{' | tee /tmp/mit/mitsuba.jsonl | tee -a $L
echo "== bench error" | tee -a $L
timeout 250 $T bench error --out $R/error --mitsuba /tmp/mit --repeats 3 2>&1 | grep -v XDG | tee -a $L
cp /tmp/mit/mitsuba.jsonl $R/error/
rm -f $R/error/*.exr
cd $OUT && tar czf res.tgz res && rm -rf res
