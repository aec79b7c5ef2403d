for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
for t in large small; do for a in 128 160 192; do
  echo "== tiles $t ablate $a"
  TREELET_SORT_ABLATE=$a TREELET_SORT_TILES=$t timeout -s KILL 30 ./treelet bench build --sizes 1000000,16000000 --repeats 5 --per-kernel 2>&1 | grep -a -E "resident|^ +1[06]000000" | tail -6
done; done
./pipeline_stats sort::sort_onesweep_cs sort::sort_onesweep_small_cs sort::sort_multisplit_cs 2>&1 | tail -8
