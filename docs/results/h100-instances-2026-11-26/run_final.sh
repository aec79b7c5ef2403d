for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 2 bunny2.ply > /dev/null
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
./treelet bench instances --scene bunny2.ply --grid 2 --top-sizes 10 --repeats 1 --width 640 --height 480 > /dev/null 2>&1
echo "== bench instances bunny4, 32x32"; ./treelet bench instances --scene bunny4.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7 --json $OUT/instances_bunny4.json 2>&1
echo "== bench instances bunny2, 32x32"; ./treelet bench instances --scene bunny2.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7 --json $OUT/instances_bunny2.json 2>&1
