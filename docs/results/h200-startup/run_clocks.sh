for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,utilization.gpu,pstate,power.draw,clocks_event_reasons.active --format=csv -lms 50 > $OUT/clocks.csv 2>&1 &
SMI=$!
mark() { echo "$(date '+%Y/%m/%d %H:%M:%S.%3N') $*" >> $OUT/marks.txt; echo "== $*"; }
sleep 1
R="--width 1024 --height 768 --spp 1024"
mark cornell-1; /usr/bin/time -f "process %e s" timeout -s KILL 60 ./treelet render --scene cornell $R --out /tmp/c1.png 2>&1 | tail -3
mark cornell-2; /usr/bin/time -f "process %e s" timeout -s KILL 60 ./treelet render --scene cornell $R --out /tmp/c2.png 2>&1 | tail -3
sleep 8
mark cornell-3-after-8s-idle; /usr/bin/time -f "process %e s" timeout -s KILL 60 ./treelet render --scene cornell $R --out /tmp/c3.png 2>&1 | tail -3
mark room-1; /usr/bin/time -f "process %e s" timeout -s KILL 60 ./treelet render --scene ../scenes/room_disk.json --width 1024 --height 768 --spp 256 --out /tmp/r1.png 2>&1 | tail -3
mark room-2; /usr/bin/time -f "process %e s" timeout -s KILL 60 ./treelet render --scene ../scenes/room_disk.json --width 1024 --height 768 --spp 256 --out /tmp/r2.png 2>&1 | tail -3
mark bench-build; timeout -s KILL 60 ./treelet bench build --sizes 1000000 --repeats 41 2>&1 | tail -3
mark bench-build-2; timeout -s KILL 60 ./treelet bench build --sizes 1000000 --repeats 41 2>&1 | tail -3
mark end
sleep 0.5; kill $SMI
