for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name --format=csv
timeout -s KILL 150 nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1 &
NV=$!
timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
timeout -s KILL 40 ./treelet_base bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for bin in treelet_base treelet treelet_base treelet; do echo "== $bin"; timeout -s KILL 60 ./$bin bench build --sizes 65536,1000000,4000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -6; done
echo "== treelet LOOK_BACK=0"; TREELET_SORT_LOOK_BACK=0 timeout -s KILL 60 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -6
wait $NV; tail -3 nvcc.log
timeout -s KILL 60 ./cub_sort
