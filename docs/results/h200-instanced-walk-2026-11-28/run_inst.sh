# Alternates builds of `bench instances` on the 940k bunny (grid 32, 1920x1080).
set -x
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply
for v in $VARIANTS; do xz -dc treelet_$v.xz > /tmp/treelet_$v; chmod +x /tmp/treelet_$v; done
for round in 1 2; do
  for v in $VARIANTS; do
    echo "=== $v round $round"
    /tmp/treelet_$v bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000,100000 --repeats 5 2>&1 | grep -v "^\s*$" | tail -8
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
