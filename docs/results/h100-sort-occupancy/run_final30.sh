for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version --format=csv
timeout -s KILL 150 nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1 &
NV=$!
echo skip
echo "== treelet tests"; timeout -s KILL 150 ./treelet_test 2>&1 | tail -3
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
echo "== bench build"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --json lbvh.json 2>&1 | tail -6
echo "== bench build --per-kernel"; timeout -s KILL 90 ./treelet bench build --sizes 65536,131072,262144,524288,1000000,4000000,16000000 --repeats 21 --per-kernel --json lbvh_per_kernel.json 2>&1 | tail -9
echo "== small tiles mid sizes"; TREELET_SORT_TILES=small timeout -s KILL 60 ./treelet bench build --sizes 131072,262144,524288 --repeats 21 --per-kernel 2>&1 | tail -3
wait $NV; tail -3 nvcc.log
echo "== CUB"; timeout -s KILL 60 ./cub_sort | tee cub.jsonl
for bin in treelet_base treelet treelet_base treelet; do
echo "== trbvh $bin"; TREELET_PROFILE_LEVELS=1 timeout -s KILL 60 ./$bin bench build --builder trbvh --sizes 1000000,4000000 --repeats 7 2>&1 | tail -4
done
cp lbvh.json lbvh_per_kernel.json cub.jsonl $OUT/ 2>/dev/null
