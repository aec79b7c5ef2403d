for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for bin in treelet treelet4 treelet treelet4; do
echo "== $bin"; TREELET_SORT_TILES=multisplit timeout -s KILL 60 ./$bin bench build --sizes 65536,262144,524288,1000000,4000000 --repeats 21 --per-kernel 2>&1 | tail -5 | awk '{print $1, $8, $10}'
done
