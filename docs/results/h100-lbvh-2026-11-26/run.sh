for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version --format=csv
timeout -s KILL 150 nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1 &
NV=$!
echo "== GPU = CPU tests (sort, trees)"; timeout -s KILL 150 ./gpu_vs_cpu 2>&1 | tail -4
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
echo "== bench build"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --json lbvh.json 2>&1 | tail -6
echo "== bench build --per-kernel"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --per-kernel --json lbvh_per_kernel.json 2>&1 | tail -6
wait $NV; tail -3 nvcc.log
echo "== CUB"; timeout -s KILL 60 ./cub_sort | tee cub.jsonl
echo "== pipeline stats"; timeout -s KILL 60 ./pipeline_stats treelet::treelet_init_cs treelet::treelet_restructure_cs treelet::collapse_cs sort::sort_onesweep_cs fit::agglomerate_cs 2>&1 | tail -8
echo "== trbvh levels 1M"; TREELET_PROFILE_LEVELS=1 timeout -s KILL 60 ./treelet bench build --builder trbvh --sizes 1000000 --repeats 5 2>&1 | tail -3
cp lbvh.json lbvh_per_kernel.json cub.jsonl $OUT/ 2>/dev/null
