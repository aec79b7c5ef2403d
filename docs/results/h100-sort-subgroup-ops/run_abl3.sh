for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for a in 0 32 288 256 0 32 288; do
  echo "== ablate $a"
  TREELET_SORT_ABLATE=$a timeout -s KILL 40 ./treelet bench build --sizes 1000000,4000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -4
done
nvidia-smi --query-gpu=clocks.sm --format=csv
