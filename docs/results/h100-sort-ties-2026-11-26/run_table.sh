for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
timeout -s KILL 150 nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1 &
NV=$!
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
echo "== issue 30 table: bench build"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --json $OUT/lbvh.json 2>&1 | tail -6
sleep 10
echo "== every digit (TREELET_SORT_HIGH_FIRST=0)"; TREELET_SORT_HIGH_FIRST=0 timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --json $OUT/lbvh_every_digit.json 2>&1 | tail -6
sleep 10
echo "== --per-kernel"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --per-kernel --json $OUT/lbvh_per_kernel.json 2>&1 | tail -6
wait $NV; tail -3 nvcc.log
echo "== CUB"; timeout -s KILL 60 ./cub_sort | tee $OUT/cub.jsonl
nvidia-smi --query-gpu=clocks.sm --format=csv
