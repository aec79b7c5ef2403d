for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
for a in 128 160 416; do
  echo "== ablate $a"
  TREELET_SORT_ABLATE=$a timeout -s KILL 40 ./treelet bench build --sizes 1000000,16000000 --repeats 3 2>&1 | grep -iE "resident|probe" | sort | uniq -c | sort -rn | head -5
done
