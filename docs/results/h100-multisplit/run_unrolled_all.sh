for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
for t in large small multisplit; do echo "== TREELET_SORT_TILES=$t bench build --per-kernel"; TREELET_SORT_TILES=$t timeout -s KILL 70 ./treelet bench build --sizes 65536,1000000,4000000,16000000 --repeats 11 --per-kernel 2>&1 | tail -4; done
