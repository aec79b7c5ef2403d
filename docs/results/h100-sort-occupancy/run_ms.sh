for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
echo "== GPU = CPU sort tests"; timeout -s KILL 150 ./gpu_vs_cpu sort 2>&1 | tail -4
./pipeline_stats 2>&1 | tail -70
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for t in multisplit large small multisplit; do
  echo "== tiles $t"
  TREELET_SORT_TILES=$t timeout -s KILL 60 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -6
done
