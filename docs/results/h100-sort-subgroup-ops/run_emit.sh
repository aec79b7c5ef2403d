for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== layout tests"; timeout -s KILL 150 ./layouts --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -5
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do for b in treelet_base treelet; do
  echo "== $b"; timeout -s KILL 90 ./$b bench rays --scene terrain:1000000 --accels lbvh --layouts bvh2,cwbvh --repeats 7 2>&1 | tail -6
done; done
