for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
R="--width 1024 --height 768 --spp 1024"
timeout -s KILL 60 ./treelet render --scene cornell --width 256 --height 192 --spp 16 --out /tmp/w.png 2>&1 | tail -1
for rep in 1; do for bin in treelet_head treelet; do for s in cornell ../scenes/room_disk.json; do echo "== $bin $s"; timeout -s KILL 90 ./$bin render --scene $s $R --out /tmp/c.png 2>&1 | tail -1; done; done; done
echo "== smallpt integrator"; for bin in treelet_head treelet; do timeout -s KILL 90 ./$bin render --scene cornell $R --integrator smallpt --out /tmp/c.png 2>&1 | tail -1; done
echo "== stats"; timeout -s KILL 60 ./pipeline_stats render::spheres::linear_cs render::full::bvh2_cs 2>&1 | tail -3
