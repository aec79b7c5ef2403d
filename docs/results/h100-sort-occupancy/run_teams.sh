for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
echo "== treelet tests"; timeout -s KILL 150 ./treelet_test 2>&1 | tail -3
echo "== warm-up"; timeout -s KILL 40 ./treelet bench build --builder trbvh --sizes 1000000 --repeats 5 2>&1 | tail -1
for bin in treelet_base treelet treelet_base treelet; do
echo "== $bin"; timeout -s KILL 60 ./$bin bench build --builder trbvh --sizes 65536,1000000,4000000 --repeats 11 2>&1 | tail -3
done
echo "== levels"; TREELET_PROFILE_LEVELS=1 timeout -s KILL 60 ./treelet bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -2
