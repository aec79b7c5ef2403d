for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== treelet tests"; timeout -s KILL 200 ./test_treelet --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -5

echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do for b in treelet_base treelet; do
  echo "== $b rays"; timeout -s KILL 90 ./$b bench rays --scene terrain:1000000 --accels lbvh,trbvh --layouts bvh2,cwbvh --repeats 5 2>&1 | grep -E "layout|lbvh|trbvh"
  echo "== $b trbvh"; timeout -s KILL 90 ./$b bench build --builder trbvh --sizes 1000000,4000000 --repeats 7 2>&1 | tail -2
done; done
echo "== per kernel"; timeout -s KILL 90 ./treelet bench build --builder trbvh --sizes 1000000,4000000 --repeats 5 --per-kernel 2>&1 | tail -3
nvidia-smi --query-gpu=clocks.sm --format=csv
