for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
timeout -s KILL 40 ./treelet bench build --sizes 1000000 --repeats 5 2>&1 | tail -1
for fig in graph2.5 graph3.5 pareto; do
  echo "== $fig"; /usr/bin/time -f "%e s" timeout -s KILL 200 ./treelet bench $fig --device gpu --out $OUT/h100 2>&1 | tail -4
done
