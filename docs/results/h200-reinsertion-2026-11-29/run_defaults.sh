#!/usr/bin/env bash
# Defaults as shipped (TRBVH with 2 reinsertion iterations on GPUs, climb 12): the suite with OptiX beside
# (no splits, the default; then splits 0.3), a scan, and one build's report.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
T=/tmp/treelet
c="--width 1920 --height 1080 --repeats 5 --layouts bvh2"
$T build --scene scenes/real/staircase.ply.xz --builder trbvh --json > $OUT/build_staircase_default.json
python3 -c "import json; d=json.load(open('$OUT/build_staircase_default.json')); print('staircase trbvh default:', d['sah_cost'], d['epo'], d['total_ms'], d['ms'])"
PYTHONPATH=/tmp/site timeout 280 $T bench rays --suite --with-optix --accels trbvh,hploc $c --json $OUT/default_optix.json > $OUT/default_optix.log 2>&1
echo "default suite with OptiX: $?"; grep -A30 "scene    view" $OUT/default_optix.log
TREELET_SPLITS=0.3 timeout 150 $T bench rays --suite --accels trbvh,hploc $c --json $OUT/default_splits03.json > $OUT/default_splits03.log 2>&1
echo "splits 0.3: $?"; grep -A30 "scene    view" $OUT/default_splits03.log | grep inside
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply > /dev/null 2>&1
$T bench rays --scene /tmp/bunny4.ply --mesh-only --accels trbvh,hploc $c 2>&1 | grep -E "^ +(trbvh|hploc) "
nvidia-smi --query-gpu=clocks.sm --format=csv
cd $OUT && tar czf defaults.tgz default_* build_* && rm -f default_* build_*
