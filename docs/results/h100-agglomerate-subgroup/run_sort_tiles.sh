for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do
for cfg in "treelet multisplit" "treelet multisplit-small" "treelet6 multisplit-small"; do
  set -- $cfg
  echo "== $1 $2"; TREELET_SORT_TILES=$2 timeout -s KILL 60 ./$1 bench build --sizes 262144,524288,1000000,2000000,4000000 --repeats 21 2>&1 | tail -5 | awk '{print $1, $4}'
done; done
for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
for r in 1 2 3; do
for cfg in "treelet multisplit" "treelet6 multisplit-small"; do
  set -- $cfg
  echo "== $1 $2"; TREELET_SORT_TILES=$2 timeout -s KILL 60 ./$1 bench build --sizes 8000000,16000000 --repeats 11 2>&1 | tail -2 | awk '{print $1, $4}'
  sleep 3
done; done
nvidia-smi --query-gpu=clocks.sm --format=csv
