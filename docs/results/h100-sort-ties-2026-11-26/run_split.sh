for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 2 bunny2.ply > /dev/null
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do
  echo "== round $r every digit"; TREELET_SORT_HIGH_FIRST=0 timeout -s KILL 60 ./treelet bench build --sizes 1000,10000,65536,1000000 --repeats 21 2>&1 | tail -5
  echo "== round $r half split"; timeout -s KILL 60 ./treelet_half bench build --sizes 1000,10000,65536,1000000 --repeats 21 2>&1 | tail -5
  echo "== round $r log2 n + 8 split"; timeout -s KILL 60 ./treelet bench build --sizes 1000,10000,65536,1000000 --repeats 21 2>&1 | tail -5
done
for b in "TREELET_SORT_HIGH_FIRST=0 ./treelet" "./treelet_half" "./treelet"; do
  echo "== bunny2 rays: $b"; env $b bench rays --scene bunny2.ply --mesh-only --accels lbvh --layouts bvh2 --repeats 5 2>&1 | tail -2
  echo "== instances top level: $b"; env $b bench instances --scene bunny2.ply --grid 8 --top-sizes 1000,10000,100000 --repeats 7 2>&1 | grep -i -E "top level" | head -4
done
echo "== table (log2 n + 8 split)"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 --json $OUT/lbvh.json 2>&1 | tail -6
nvidia-smi --query-gpu=clocks.sm --format=csv
