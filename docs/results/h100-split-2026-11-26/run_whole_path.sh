for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
(python3 subdivide.py bunny.obj 7 bunny7.ply > /dev/null; echo "bunny7 made") &
./treelet bench rays --scene bunny4.ply --mesh-only --accels lbvh --layouts bvh2 --width 640 --height 480 --repeats 3 > /dev/null 2>&1
for r in 1 2 3; do for t in treelet_split treelet; do echo "== $t rays bunny4 (round $r)"; ./$t bench rays --scene bunny4.ply --mesh-only --accels lbvh,hploc --layouts bvh2 --width 1920 --height 1080 --repeats 7 2>&1 | grep -E "^ +(lbvh|hploc) "; done; done
wait
echo "== bench rays bunny7 (60.2M, split path)"; ./treelet bench rays --scene bunny7.ply --mesh-only --accels lbvh --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | tail -2
