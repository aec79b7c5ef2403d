#!/bin/bash
# One H100 lease for issue 19: wall against kernel time (pipeline cache), GPU = CPU render tests,
# Mitsuba 3's renders of the room, then `treelet bench error` with Mitsuba beside.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
for f in .run/*.xz $(ls .run/tests/*.xz 2>/dev/null); do xz -dkf $f; chmod +x ${f%.xz}; done
T=.run/treelet; L=$OUT/log.txt; R=$OUT/res; mkdir -p $R /tmp/mit
nvidia-smi --query-gpu=name,driver_version --format=csv | tee $L
python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]" &
echo "== warm-up process (discarded)" | tee -a $L
TREELET_PIPELINE_CACHE=off $T render --width 64 --height 48 --spp 4 --out /tmp/w.png 2>&1 | grep -v XDG | tail -1 | tee -a $L
echo "== README render: no pipeline cache, then a new cache, then loaded (x3), each integrator" | tee -a $L
W="--width 1024 --height 768 --spp 1024 --explain"
for i in 1 2; do TREELET_PIPELINE_CACHE=off /usr/bin/time -f "process wall %e s" $T render $W --out /tmp/x.png --report $R/wall_off_$i.json 2>&1 | grep -E "start-up|process|cornell" | tee -a $L; done
export TREELET_PIPELINE_CACHE=/tmp/plc
for i in new 1 2 3; do /usr/bin/time -f "process wall %e s" $T render $W --out /tmp/x.png --report $R/wall_cache_$i.json 2>&1 | grep -E "start-up|process|cornell" | tee -a $L; done
for i in 1 2; do /usr/bin/time -f "process wall %e s" $T render $W --integrator smallpt --out /tmp/x.png --report $R/wall_smallpt_$i.json 2>&1 | grep -E "start-up|process|cornell" | tee -a $L; done
ls -la /tmp/plc | tee -a $L
echo "== render tests (GPU = CPU)" | tee -a $L
mkdir -p /work/main/tests && ln -sfn $PWD/scenes /work/main/scenes
[ -x .run/tests/render ] && CI=1 timeout 200 .run/tests/render --test-threads 4 2>&1 | grep -E "^test |test result|panicked|agree" | tee -a $L
wait
echo "== mitsuba" | tee -a $L
PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 200 python3 peers/mitsuba/room_disk.py /tmp/mit 16,64,256,1024,4096 2>&1 | grep '^{' | tee /tmp/mit/mitsuba.jsonl | tee -a $L
echo "== bench error" | tee -a $L
timeout 330 $T bench error --out $R/error --mitsuba /tmp/mit --repeats 3 2>&1 | grep -v XDG | tee -a $L
cp /tmp/mit/mitsuba.jsonl $R/error/
rm -f $R/error/*.exr
cd $OUT && tar czf res.tgz res && rm -rf res
