for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== gpu_vs_cpu"; timeout -s KILL 200 ./gpu_vs_cpu --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -5
echo "== layouts"; timeout -s KILL 150 ./layouts --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -5
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do
  for h in agglomerative subgroup; do
  echo "== $h"; TREELET_HIERARCHY=$h timeout -s KILL 90 ./treelet bench build --sizes 65536,131072,262144,1000000,4000000,16000000 --repeats 21 --json lbvh_$h.json 2>&1 | tail -6
  done
done
echo "== default, per kernel"; timeout -s KILL 90 ./treelet bench build --sizes 65536,131072,1000000,4000000,16000000 --repeats 21 --per-kernel --json lbvh_per_kernel.json 2>&1 | tail -6
echo "== trbvh"; timeout -s KILL 90 ./treelet bench build --builder trbvh --sizes 1000000,4000000 --repeats 11 2>&1 | tail -3
echo "== rays"; timeout -s KILL 90 ./treelet bench rays --scene terrain:1000000 --accels lbvh,trbvh --layouts bvh2 --repeats 7 2>&1 | tail -3
nvidia-smi --query-gpu=clocks.sm --format=csv
cp *.json $OUT/ 2>/dev/null
