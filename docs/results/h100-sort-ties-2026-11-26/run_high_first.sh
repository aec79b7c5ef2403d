for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
timeout -s KILL 150 nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1 &
NV=$!
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do for hf in 0 1; do
  echo "== round $r TREELET_SORT_HIGH_FIRST=$hf"; TREELET_SORT_HIGH_FIRST=$hf timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 2>&1 | tail -5
done; done
echo "== table per kernel (high first)"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --per-kernel --json lbvh_per_kernel.json 2>&1 | tail -6
echo "== table (high first)"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --json lbvh.json 2>&1 | tail -6
for hf in 0 1; do
  echo "== bunny4 rays TREELET_SORT_HIGH_FIRST=$hf"; TREELET_SORT_HIGH_FIRST=$hf timeout -s KILL 90 ./treelet bench rays --scene bunny4.ply --mesh-only --accels lbvh,trbvh --layouts bvh2 --repeats 5 2>&1 | tail -8
  echo "== instances top level TREELET_SORT_HIGH_FIRST=$hf"; TREELET_SORT_HIGH_FIRST=$hf timeout -s KILL 90 ./treelet bench instances --scene bunny4.ply --grid 8 --top-sizes 1000,10000,100000 --repeats 7 2>&1 | grep -i -E "top|stage|sort" | head -12
done
wait $NV; tail -3 nvcc.log
echo "== CUB"; timeout -s KILL 60 ./cub_sort | tee cub.jsonl
nvidia-smi --query-gpu=clocks.sm --format=csv
cp lbvh.json lbvh_per_kernel.json cub.jsonl $OUT/ 2>/dev/null
echo "== gpu_vs_cpu on the device"; cd .. && timeout -s KILL 200 ./.dev/test_gpu_vs_cpu --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked|subgroups" | head -8
