for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== GPU = CPU tests"; timeout -s KILL 150 ./gpu_vs_cpu --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -5
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do for b in treelet_base treelet; do
  echo "== $b"; timeout -s KILL 60 ./$b bench build --sizes 65536,1000000,4000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -5
done; done
nvidia-smi --query-gpu=clocks.sm --format=csv
