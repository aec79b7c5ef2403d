for f in treelet.xz treelet_prev.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
(python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null 2>&1 &)
for round in 1 2 3; do
 for b in treelet_prev treelet; do
  echo "== $b round $round"
  ./$b bench build --sizes 65536,1000000 --repeats 21 2>&1 | grep -E "^ +[0-9]+ " | head -2
  ./$b bench build --builder trbvh --sizes 1000000 --repeats 11 2>&1 | grep -E "^ +[0-9]+ " | head -1
 done
done
sleep 20; ls -la bunny4.ply
for round in 1 2; do
for b in treelet_prev treelet; do
  echo "== instances $b"
  ./$b bench instances --scene bunny4.ply --grid 8 --top-sizes 1000,10000,100000 2>&1 | grep -E "top level" | head -4
  ./$b bench rays --scene bunny4.ply --mesh-only --accels lbvh --layouts bvh2 --width 1920 --height 1080 2>&1 | grep -iE "layout|build|depth" | head -4
done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
