for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
echo "== warm-up"; timeout -s KILL 40 ./treelet_l3 bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for r in 1 2; do for b in treelet_l3 treelet_l1; do
  echo "== $b rays"; timeout -s KILL 90 ./$b bench rays --scene terrain:1000000 --accels lbvh --layouts bvh2 --repeats 5 2>&1 | grep -E "collapse"
  echo "== $b rays 4M"; timeout -s KILL 90 ./$b bench rays --scene terrain:4000000 --accels lbvh --layouts bvh2 --repeats 5 2>&1 | grep -E "collapse"
  echo "== $b per kernel"; timeout -s KILL 90 ./$b bench build --builder trbvh --sizes 1000000,4000000 --repeats 5 --per-kernel 2>&1 | tail -2 | awk '{print $1, $(NF-9), $(NF-8)}'
done; done
