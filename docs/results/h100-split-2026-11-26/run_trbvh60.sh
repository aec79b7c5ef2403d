for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
(python3 subdivide.py bunny.obj 7 bunny7.ply > /dev/null; echo "bunny7 made") &
for r in 1 2; do for t in treelet_old treelet; do echo "== $t bench build trbvh (round $r)"; ./$t bench build --builder trbvh --sizes 1000000,4000000 --repeats 7 2>&1 | grep -E "^ +[0-9]"; done; done
wait
echo "== build trbvh bunny7 (60.2M)"; /usr/bin/time -f "process %e s, %M KB" ./treelet build --builder trbvh --scene bunny7.ply 2>&1 | grep -vE "^device"
echo "== bench rays bunny7 trbvh"; ./treelet bench rays --scene bunny7.ply --mesh-only --accels trbvh --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | tail -3
