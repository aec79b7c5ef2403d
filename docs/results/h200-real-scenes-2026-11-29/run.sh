#!/usr/bin/env bash
# Treelet's `bench rays` and OptiX's (peers/mitsuba/rays.py) on the same GPU, one call, for the scenes
# named: outside (the mesh-only framing) and inside (MANIFEST.json's camera), splits off and on.
# usage: run.sh SCENE..   (names of .dev/carry/scenes/NAME.ply.xz, or city_300k / city_1m, generated)
set -x
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
mkdir -p /tmp/s $OUT/j
T=/tmp/treelet
common="--width 1920 --height 1080 --repeats 5"
for name in "$@"; do
  set +x
  case $name in
    city_300k) $T export --scene city:300000 --out /tmp/s/$name.ply; cam="" ;;
    city_1m) $T export --scene city:1000000 --out /tmp/s/$name.ply; cam="" ;;
    *) xz -dc .dev/carry/scenes/$name.ply.xz > /tmp/s/$name.ply
       cam=$(python3 -c "import json; m=[m for m in json.load(open('.dev/carry/scenes/MANIFEST.json'))['models'] if m['name']=='$name'][0]['camera']; print(','.join(str(x) for x in m['eye']+m['look_at']))") ;;
  esac
  ply=/tmp/s/$name.ply
  for view in outside inside; do
    if [ $view = inside ]; then [ -z "$cam" ] && continue; camarg="--camera $cam"; pycam=$cam; else camarg=""; pycam=""; fi
    echo "=== $name $view: treelet, no splits"
    TREELET_SPLITS=0 $T bench rays --scene $ply --mesh-only $camarg --accels lbvh,hploc,trbvh --layouts bvh2,cwbvh $common --json $OUT/j/r_${name}_${view}_0.json 2>&1 | grep -v "layout of the\|^$"
    echo "=== $name $view: treelet, splits 0.3"
    TREELET_SPLITS=0.3 $T bench rays --scene $ply --mesh-only $camarg --accels lbvh,hploc,trbvh --layouts bvh2,cwbvh $common --json $OUT/j/r_${name}_${view}_03.json 2>&1 | grep -v "layout of the\|^$"
    echo "=== $name $view: OptiX"
    PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1 python3 peers/mitsuba/rays.py $ply 1920 1080 5 $pycam 2>&1 | tail -2 >> $OUT/j/optix.jsonl; tail -1 $OUT/j/optix.jsonl
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
(cd $OUT && tar cJf results.tar.xz j && rm -rf j)
