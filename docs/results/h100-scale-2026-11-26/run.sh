for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
timeout -s KILL 60 ./treelet bench build --sizes 1000000 --repeats 3 2>&1 | tail -1
for n in 832000 3300000 13300000; do echo "== terrain:$n"; timeout -s KILL 150 ./treelet bench rays --scene terrain:$n --mesh-only --accels lbvh,trbvh --layouts bvh2,cwbvh --width 640 --height 480 --repeats 3 2>&1 | grep -E "layout of|lbvh|trbvh" | tail -8; done
