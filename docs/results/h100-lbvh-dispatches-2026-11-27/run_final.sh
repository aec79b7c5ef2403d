for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
timeout -s KILL 150 nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort > nvcc.log 2>&1 &
NV=$!
(python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null 2>&1 &)
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
echo "== issue 30 table: bench build (new)"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --json $OUT/lbvh.json 2>&1 | tail -6
echo "== --per-kernel (new)"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --per-kernel --json $OUT/lbvh_per_kernel.json 2>&1 | tail -6
wait $NV; tail -3 nvcc.log
echo "== CUB"; timeout -s KILL 60 ./cub_sort | tee $OUT/cub.jsonl
for round in 1 2 3; do
 for b in treelet_old treelet; do
  echo "== $b round $round"
  ./$b bench build --sizes 65536,1000000,4000000 --repeats 21 2>&1 | grep -E "^ +[0-9]+ " | head -4
 done
done
echo "== tests on the H100"
(cd .. && for t in gpu_vs_cpu instances tracer; do ./.dev/test_$t 2>&1 | tail -3; done)
wait; ls -la bunny4.ply
for b in treelet_old treelet; do
  echo "== instances $b"
  ./$b bench instances --scene bunny4.ply --grid 8 --top-sizes 1000,10000,100000 2>&1 | grep -E "top level" | head -4
done
nvidia-smi --query-gpu=clocks.sm --format=csv
