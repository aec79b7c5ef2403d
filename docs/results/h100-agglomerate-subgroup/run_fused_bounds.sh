for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== gpu_vs_cpu"; timeout -s KILL 200 ./test_gpu_vs_cpu --test-threads 2 2>&1 | grep -E "test result|FAILED|panicked" | head -5
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do for b in treelet_base treelet; do
  echo "== $b"; timeout -s KILL 60 ./$b bench build --sizes 65536,1000000,4000000 --repeats 21 2>&1 | tail -3
done; done
for b in treelet_base treelet; do echo "== $b 16M"; timeout -s KILL 60 ./$b bench build --sizes 16000000 --repeats 11 2>&1 | tail -1; sleep 4; done
echo "== per kernel"; timeout -s KILL 60 ./treelet bench build --sizes 65536,1000000,4000000 --repeats 21 --per-kernel 2>&1 | tail -4
nvidia-smi --query-gpu=clocks.sm --format=csv
