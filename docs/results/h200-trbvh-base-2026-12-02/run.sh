#!/usr/bin/env bash
# The TRBVH's cost against its gain: fewer treelet rounds, fewer reinsertion iterations, and the
# rounds over H-PLOC's tree instead of the radix tree (TREELET_HIERARCHY=hploc), on the suite,
# each run alternated with the defaults; OptiX once, in the same call.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/T; chmod +x /tmp/T
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
mkdir -p /tmp/j
c="--suite --width 1920 --height 1080 --repeats 5 --layouts bvh2,cwbvh"
T0=$(date +%s)
run() { name=$1; acc=$2; shift 2; s=$(date +%s); if [ $((s - T0)) -gt 500 ]; then echo "$name skipped (time)"; return; fi; env "$@" timeout 90 /tmp/T bench rays $c --accels $acc ${X:-} --json /tmp/j/$name.json > /tmp/j/$name.log 2>&1; echo "$name rc=$? $(( $(date +%s) - s ))s"; tail -1 /tmp/j/$name.log; }
X=--with-optix run O trbvh,hploc PYTHONPATH=/tmp/site TREELET_SPLITS=0.3
run D1 trbvh TREELET_SPLITS=0.3
run T1R1 trbvh TREELET_TREELETS=1,3,8 TREELET_REINSERT=1
run T2R1 trbvh TREELET_TREELETS=2,3,8 TREELET_REINSERT=1
run T3R1 trbvh TREELET_REINSERT=1
run T3G7 trbvh TREELET_TREELETS=3,7,8
run H1R0 trbvh TREELET_HIERARCHY=hploc TREELET_TREELETS=1,3,8 TREELET_REINSERT=0
run H1R1 trbvh TREELET_HIERARCHY=hploc TREELET_TREELETS=1,3,8 TREELET_REINSERT=1
run H2R1 trbvh TREELET_HIERARCHY=hploc TREELET_TREELETS=2,3,8 TREELET_REINSERT=1
run H3R2 trbvh TREELET_HIERARCHY=hploc
run H1G7R1 trbvh TREELET_HIERARCHY=hploc TREELET_TREELETS=1,7,8 TREELET_REINSERT=1
run D2 trbvh TREELET_SPLITS=0.3
tar czf $OUT/runs.tgz -C /tmp/j .

nvidia-smi --query-gpu=clocks.sm --format=csv
