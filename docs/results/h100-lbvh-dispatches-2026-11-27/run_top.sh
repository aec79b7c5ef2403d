for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null 2>&1
for round in 1 2 3; do
for b in treelet_prev treelet; do
  echo "== instances $b round $round"
  ./$b bench instances --scene bunny4.ply --grid 8 --top-sizes 1000,10000,100000 2>&1 | grep -E "top level" | head -4
done
done
(cd .. && for t in instances tracer; do ./.dev/test_$t 2>&1 | tail -3; done)
nvidia-smi --query-gpu=clocks.sm --format=csv
