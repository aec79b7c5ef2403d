for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== tests, 8 workgroups for the fit"; TREELET_FIT_GROUPS=8 timeout -s KILL 120 ./gpu_vs_cpu --test-threads 2 lbvh agglomerat repeated 2>&1 | tail -4
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do
echo "== base"; timeout -s KILL 40 ./treelet_base bench build --sizes 1000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -3
for g in 0 264 528 1056 2112; do
  echo "== fit groups $g"; TREELET_FIT_GROUPS=$g timeout -s KILL 40 ./treelet bench build --sizes 1000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -3
done
done
for a in 0 32 64 1 2 4 8 6 14 0; do
  echo "== ablate $a"
  TREELET_SORT_ABLATE=$a timeout -s KILL 40 ./treelet bench build --sizes 1000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -3
done
nvidia-smi --query-gpu=clocks.sm --format=csv
