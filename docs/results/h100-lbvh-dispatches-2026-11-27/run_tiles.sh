for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
(python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null 2>&1 &)
for round in 1 2 3; do
 for b in treelet_prev treelet; do
  echo "== $b round $round"
  ./$b bench build --sizes 65536,100000,200000,1000000 --repeats 21 2>&1 | grep -E "^ +[0-9]+ " | head -4
 done
done
(cd .. && ./.dev/test_gpu_vs_cpu 2>&1 | tail -3)
sleep 3; ls -la bunny4.ply
for b in treelet_prev treelet; do
  echo "== instances $b"
  ./$b bench instances --scene bunny4.ply --grid 8 --top-sizes 1000,10000,100000 2>&1 | grep -E "top level" | head -4
done
nvidia-smi --query-gpu=clocks.sm --format=csv
