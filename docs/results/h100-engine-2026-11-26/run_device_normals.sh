for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
timeout -s KILL 60 ./treelet bench build --sizes 1000000 --repeats 3 2>&1 | tail -1
echo "== bench dynamic, 11 frames"; timeout -s KILL 120 ./treelet bench dynamic --frames 11 2>&1 | tail -7
echo "== bench rays terrain:1000000"; timeout -s KILL 120 ./treelet bench rays --scene terrain:1000000 --mesh-only --layouts bvh2 --width 1920 --height 1080 --repeats 7 2>&1 | tail -3
R="--width 1024 --height 768 --spp 1024"
for s in cornell ../scenes/room_disk.json; do timeout -s KILL 90 ./treelet render --scene $s $R --out /tmp/c.png 2>&1 | tail -1; done
