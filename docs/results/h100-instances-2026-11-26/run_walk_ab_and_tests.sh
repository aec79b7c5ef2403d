for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== GPU = CPU tests (instances)"; (cd ..; CI=true ./.dev/test_instances 2>&1 | tail -8)
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
echo "== bench instances terrain:100000, 32x32"; ./treelet bench instances --scene terrain:100000 --grid 32 --top-sizes 1000,10000,100000 --repeats 7 2>&1
echo "== bench instances bunny4, 32x32"; ./treelet bench instances --scene bunny4.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7 --json $OUT/instances_bunny4.json 2>&1
./treelet_old bench rays --scene bunny4.ply --mesh-only --accels lbvh --layouts bvh2 --width 640 --height 480 --repeats 3 > /dev/null 2>&1
for r in 1 2 3; do for t in treelet_old treelet; do echo "== $t rays bunny4 (round $r)"; ./$t bench rays --scene bunny4.ply --mesh-only --accels lbvh,trbvh --layouts bvh2 --width 1920 --height 1080 --repeats 7 2>&1 | grep -E "^ +(lbvh|trbvh) "; done; done
echo "== bench dynamic bunny4 (occlusion vs closest, refit)"; ./treelet bench dynamic --scene bunny4.ply --frames 7 2>&1 | tail -8
