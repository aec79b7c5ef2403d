for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
timeout -s KILL 150 nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1 &
NV=$!
echo "== layouts"; timeout -s KILL 150 ./test_layouts --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -5
echo "== treelet"; timeout -s KILL 150 ./test_treelet --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -5
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
echo "== bench build (table)"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --json lbvh.json 2>&1 | tail -6
sleep 8
echo "== bench build --per-kernel (table)"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --per-kernel --json lbvh_per_kernel.json 2>&1 | tail -6
echo "== trbvh"; timeout -s KILL 90 ./treelet bench build --builder trbvh --sizes 1000000,4000000 --repeats 11 2>&1 | tail -3
echo "== rays"; timeout -s KILL 90 ./treelet bench rays --scene terrain:1000000 --accels lbvh,trbvh --layouts bvh2,cwbvh --repeats 5 2>&1 | tail -6
wait $NV; tail -3 nvcc.log
echo "== CUB"; timeout -s KILL 60 ./cub_sort | tee cub.jsonl
nvidia-smi --query-gpu=clocks.sm --format=csv
cp lbvh.json lbvh_per_kernel.json cub.jsonl $OUT/ 2>/dev/null
