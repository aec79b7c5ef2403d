for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
R="--width 1024 --height 768 --spp 64"
for bin in treelet_base treelet treelet_base treelet; do
  for s in cornell ../scenes/room_disk.json; do echo "== cold $bin $s"; __GL_SHADER_DISK_CACHE=0 TREELET_PIPELINE_CACHE=off /usr/bin/time -f "process %e s" timeout -s KILL 60 ./$bin render --scene $s $R --explain --out /tmp/c.png 2>&1 | tail -4; done
done
echo "== warm caches treelet room x2"; for i in 1 2; do /usr/bin/time -f "process %e s" timeout -s KILL 60 ./treelet render --scene ../scenes/room_disk.json $R --explain --out /tmp/c.png 2>&1 | tail -4; done
echo "== pipeline stats"; timeout -s KILL 60 ./pipeline_stats sort::sort_onesweep_cs sort::sort_onesweep_small_cs sort::sort_multisplit_cs sort::sort_histogram_cs fit::agglomerate_cs morton::morton_cs scene::primitive_boxes_cs bounds::reduce_bounds_cs 2>&1 | tail -12
