#!/usr/bin/env bash
# Parallel reinsertion (TREELET_REINSERT iterations after the treelet rounds / over H-PLOC's tree) on the
# real-scene suite, splits 0.3 (the best of last session) and 0; OptiX beside once.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2"
# Moves per iteration and SAH/EPO, one scene per kind.
[ -z "$NOBUILD" ] && for s in scenes/real/staircase.ply.xz scenes/real/classroom.ply.xz city:1000000; do
  for r in 0 8; do
    TREELET_SPLITS=0.3 TREELET_PROFILE_REINSERT=1 /tmp/treelet build --scene $s --builder trbvh --reinsert $r --json > $OUT/build_$(basename $s)_$r.json 2> $OUT/build_$(basename $s)_$r.err
  done
done
for r in ${REINSERTS:-0 4 8}; do
  TREELET_SPLITS=0.3 TREELET_REINSERT=$r timeout 150 /tmp/treelet bench rays --suite --accels trbvh,hploc $c --json $OUT/re_03_$r.json > $OUT/re_03_$r.log 2>&1
  echo "splits 0.3 reinsert $r: $?"
done
[ -n "$OPTIX" ] && TREELET_SPLITS=0.3 TREELET_REINSERT=$OPTIX PYTHONPATH=/tmp/site timeout 240 /tmp/treelet bench rays --suite --with-optix --accels trbvh $c --json $OUT/re_03_8_optix.json > $OUT/re_03_8_optix.log 2>&1
echo "optix: $?"
nvidia-smi --query-gpu=clocks.sm --format=csv
