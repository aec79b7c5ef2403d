for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
echo "== test"; timeout -s KILL 120 ./gpu_vs_cpu agglomerative 2>&1 | grep -E "test result|FAILED|panicked" | head -5
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for cfg in "8 0" "4 0" "6 0" "12 0" "8 1" "8 2"; do
  set -- $cfg
  echo "== rounds $1 ablate $2"; TREELET_AGG_ROUNDS=$1 TREELET_AGG_ABLATE=$2 timeout -s KILL 60 ./treelet bench build --sizes 65536,1000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -3 | awk '{print $1, $(NF-4), $(NF-3), $(NF-2)}'
done
for r in 1 2; do
  echo "== base"; timeout -s KILL 90 ./treelet_base bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 2>&1 | tail -4
  echo "== subgroup + queues"; timeout -s KILL 90 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 21 2>&1 | tail -4
done
