for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,clocks.sm,clocks.mem --format=csv
timeout -s KILL 150 nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1 &
NV=$!
echo "== warm-up (first process)"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 3 2>&1 | tail -2
echo "== sort tests"; timeout -s KILL 120 ./gpu_vs_cpu sort 2>&1 | tail -4
for bin in treelet_base treelet; do for t in large small; do echo "== $bin TREELET_SORT_TILES=$t --per-kernel"; TREELET_SORT_TILES=$t timeout -s KILL 60 ./$bin bench build --sizes 65536,1000000,4000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -6; done; done
wait $NV; tail -3 nvcc.log
timeout -s KILL 60 ./cub_sort
