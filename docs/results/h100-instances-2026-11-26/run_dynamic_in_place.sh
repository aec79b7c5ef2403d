for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
./treelet bench rays --scene terrain:1000000 --mesh-only --accels lbvh --layouts bvh2 --width 640 --height 480 --repeats 3 > /dev/null 2>&1
echo "== bench dynamic terrain:1000000"; ./treelet bench dynamic --scene terrain:1000000 --frames 7 --json $OUT/dynamic_terrain.json 2>&1 | tail -7
echo "== bench dynamic bunny4"; ./treelet bench dynamic --scene bunny4.ply --frames 7 --json $OUT/dynamic_bunny4.json 2>&1 | tail -7
echo "== bench rays terrain:1000000 (same rays? no: camera framing; for scale)"; ./treelet bench rays --scene terrain:1000000 --mesh-only --accels trbvh --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | grep -E "^ +trbvh"
