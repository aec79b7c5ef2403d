for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
python3 subdivide.py bunny.obj 2 bunny2.ply > /dev/null
# Warm-up process (pipeline caches, clocks).
./treelet bench instances --scene bunny2.ply --grid 2 --top-sizes 10 --repeats 1 --width 640 --height 480 > /dev/null 2>&1
for round in 1 2; do
  echo "== round $round: old (febdd4e) bench instances bunny4 32x32"
  ./treelet_old bench instances --scene bunny4.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7 2>&1
  echo "== round $round: new bench instances bunny4 32x32"
  ./treelet bench instances --scene bunny4.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7 --json $OUT/instances_bunny4_r$round.json 2>&1
done
echo "== instance tests on the GPU (debug test binary, CI=true)"
cd .. && CI=true ./.dev/instances_test 2>&1 | tail -8
