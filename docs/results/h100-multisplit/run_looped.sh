for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
cd .dev
(nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1; echo nvcc rc $?) &
echo "== tests sort"; timeout -s KILL 150 ./gpu_vs_cpu --test-threads 1 sort subgroup 2>&1 | tail -40
./treelet bench build --sizes 1000000 --repeats 5 > /dev/null 2>&1
for t in large multisplit; do echo "== TREELET_SORT_TILES=$t bench build --per-kernel"; TREELET_SORT_TILES=$t timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --per-kernel 2>&1 | tail -6; done
wait
echo "== cub"; timeout 60 ./cub_sort 65536,1000000,4000000,16000000
echo "== bench build (default)"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 2>&1 | tail -6
echo "== treelet tests"; timeout -s KILL 100 ./treelet_t --test-threads 1 2>&1 | tail -3
echo "== invariants tests"; timeout -s KILL 100 ./invariants --test-threads 1 2>&1 | tail -3
