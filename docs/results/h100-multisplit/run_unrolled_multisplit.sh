for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
nvidia-smi --query-gpu=name,driver_version --format=csv
cd .dev
(nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1; echo nvcc rc $?) &
echo "== tests sort"; timeout -s KILL 60 ./gpu_vs_cpu --test-threads 1 sort 2>&1 | tail -8
timeout 20 ./treelet bench build --sizes 1000000 --repeats 5 > /dev/null 2>&1
for t in large multisplit; do echo "== TREELET_SORT_TILES=$t bench build --per-kernel"; TREELET_SORT_TILES=$t timeout -s KILL 50 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -5; done
wait
echo "== cub"; timeout 40 ./cub_sort 65536,1000000,4000000,16000000
