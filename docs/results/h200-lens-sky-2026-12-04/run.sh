#!/usr/bin/env bash
# The environment's code in the general render kernel: `bench variants` (each scene's variant and
# the general kernel, 1024x768 at 64 spp) with the binary before (A) and after (B) the lens and the
# sky, alternated; then scenes/lens_sky.json rendered for the README.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_a.xz > /tmp/A; xz -dc .dev/carry/treelet.xz > /tmp/B; chmod +x /tmp/A /tmp/B
mkdir -p $OUT/json
for round in 1 2; do
  for bin in A B; do
    /tmp/$bin bench variants --repeats 5 --json $OUT/json/variants_${bin}_$round.json > $OUT/variants_${bin}_$round.txt 2>&1
    echo "== $bin round $round rc=$?"; grep -v '^ *$' $OUT/variants_${bin}_$round.txt | tail -9
  done
done
/tmp/B render --scene scenes/lens_sky.json --width 960 --height 540 --spp 4096 --explain --out $OUT/lens_sky_4096spp.png 2>&1 | tail -4
/tmp/B render --scene scenes/lens_sky.json --width 960 --height 540 --spp 1024 --device gpu --out $OUT/lens_sky_1024spp_gpu.png 2>&1 | tail -1
nvidia-smi --query-gpu=clocks.sm --format=csv
