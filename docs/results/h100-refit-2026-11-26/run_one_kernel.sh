for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
for r in 1 2; do for b in treelet_old treelet; do
  echo "== round $r: $b bench dynamic terrain:1000000"; timeout -s KILL 150 ./$b bench dynamic --scene terrain:1000000 --frames 7 2>&1 | tail -6
done; done
for b in treelet_old treelet; do
  echo "== $b bench dynamic bunny4"; timeout -s KILL 150 ./$b bench dynamic --scene bunny4.ply --frames 7 2>&1 | tail -6
done
nvidia-smi --query-gpu=clocks.sm --format=csv
cd ..
for t in layouts tracer instances; do echo "== test $t on the device"; timeout -s KILL 200 ./.dev/test_$t --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked|^seed" | head -6; done
