for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name --format=csv,noheader
timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 3 2>&1 | tail -1
for b in lbvh trbvh; do echo "== $b"; timeout -s KILL 90 ./treelet bench build --builder $b --sizes 4096,16384,65536,262144,1000000,4000000 --repeats 11 2>&1 | tail -7; done
