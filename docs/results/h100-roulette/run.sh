#!/bin/bash
# One H100 call: Russian roulette for NEE (pbrt-v4's rule) and black surfaces ending paths,
# before against after; GPU = CPU render tests; Mitsuba 3 and `treelet bench error` with the new binary.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json XDG_RUNTIME_DIR=/tmp
for f in .run/*.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
L=$OUT/log.txt; R=$OUT/res; mkdir -p $R /tmp/mit
nvidia-smi --query-gpu=name,driver_version --format=csv | tee $L
python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]" &
export TREELET_PIPELINE_CACHE=/tmp/plc
echo "== warm-up (discarded): compile each binary's kernels" | tee -a $L
for T in .run/treelet_before .run/treelet; do for s in cornell scenes/room_disk.json; do for i in nee smallpt; do
  $T render --scene $s --integrator $i --width 64 --height 48 --spp 4 --out /tmp/w.png 2>&1 | tail -1 >> $R/warm.txt; done; done; done
echo "== before / after, 1024x768, 1024 spp, twice each" | tee -a $L
for k in 1 2; do for s in cornell scenes/room_disk.json; do for i in nee smallpt; do for T in .run/treelet_before .run/treelet; do
  echo -n "$T: " | tee -a $L; /usr/bin/time -f "  process wall %e s" $T render --scene $s --integrator $i --width 1024 --height 768 --spp 1024 --out /tmp/x.png 2>&1 | grep -v XDG | tail -2 | tee -a $L
done; done; done; done
wait
echo "== mitsuba" | tee -a $L
PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 120 python3 peers/mitsuba/room_disk.py /tmp/mit 16,64,256,1024,4096 2>&1 | grep '^{' | tee /tmp/mit/mitsuba.jsonl | tee -a $L
echo "== bench error" | tee -a $L
timeout 250 .run/treelet bench error --out $R/error --mitsuba /tmp/mit --repeats 3 2>&1 | grep -v XDG | tee -a $L
cp /tmp/mit/mitsuba.jsonl $R/error/
echo "== render tests (GPU = CPU)" | tee -a $L
[ -e /work/main ] || { mkdir -p /work; ln -s $PWD /work/main; }
(cd /work/main/tests && CI=1 timeout 90 /work/main/.run/render_test --test-threads 4 2>&1 | grep -E "^test |test result|panicked|seed" | tee -a $L)
rm -f $R/error/*.exr
cd $OUT && tar czf res.tgz res && rm -rf res
