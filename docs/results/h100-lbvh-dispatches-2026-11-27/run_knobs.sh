for f in treelet.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
(python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null 2>&1 &)
for round in 1 2; do
for h in agglomerative subgroup; do
 for t in small multisplit-small; do
  echo "== hierarchy $h tiles $t round $round"
  TREELET_HIERARCHY=$h TREELET_SORT_TILES=$t ./treelet bench build --sizes 65536,100000,131072,200000 --repeats 21 2>&1 | grep -E "^ +[0-9]+ " | head -4
 done
done
done
sleep 5; ls -la bunny4.ply
for h in agglomerative subgroup; do
 for t in small multisplit-small; do
  echo "== instances hierarchy $h tiles $t"
  TREELET_HIERARCHY=$h TREELET_SORT_TILES=$t ./treelet bench instances --scene bunny4.ply --grid 8 --top-sizes 10000,100000 2>&1 | grep -E "top level" | head -3
 done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
