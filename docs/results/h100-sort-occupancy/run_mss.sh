for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
echo "== GPU = CPU tests"; timeout -s KILL 150 ./gpu_vs_cpu 2>&1 | tail -3
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for bin in treelet_base treelet treelet_base treelet; do
echo "== $bin"; timeout -s KILL 60 ./$bin bench build --sizes 65536,262144,524288,750000,1000000,4000000 --repeats 21 --per-kernel 2>&1 | tail -7
done
