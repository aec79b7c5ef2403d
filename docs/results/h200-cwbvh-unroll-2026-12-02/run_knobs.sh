#!/usr/bin/env bash
# Main's binary (8620e5d): the cwbvh DP's cost ratio (TREELET_WIDE_COSTS) and the TRBVH's largest leaf (TREELET_TREELETS), alternately with the defaults.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_o.xz > /tmp/O; chmod +x /tmp/O
mkdir -p /tmp/j
c="--width 1920 --height 1080 --repeats 5 --accels trbvh"
run() { name=$1; s=$(date +%s); env "$2" timeout 60 /tmp/O bench rays --suite $c --layouts $3 --json /tmp/j/$name.json > /tmp/$name.log 2>&1; echo "$name rc=$? $(( $(date +%s) - s ))s"; tail -2 /tmp/$name.log; }
run D1 TREELET_SPLITS=0.3 bvh2,cwbvh
run W015 TREELET_WIDE_COSTS=1,0.15 cwbvh
run W06 TREELET_WIDE_COSTS=1,0.6 cwbvh
run W1 TREELET_WIDE_COSTS=1,1 cwbvh
run L4 TREELET_TREELETS=3,3,4 bvh2,cwbvh
run L16 TREELET_TREELETS=3,3,16 bvh2,cwbvh
run D2 TREELET_SPLITS=0.3 bvh2,cwbvh
c="--width 1920 --height 1080 --repeats 5 --accels hploc"
run H0 TREELET_SPLITS=0.3 bvh2,cwbvh
run H1 TREELET_REINSERT=1 bvh2,cwbvh
run H2 TREELET_REINSERT=2 bvh2,cwbvh
xz -dc .dev/carry/engine_frames2.xz > /tmp/ef; chmod +x /tmp/ef
for g in 256 1024 2048; do echo "== engine_frames grid $g"; timeout 120 /tmp/ef 60 /tmp/ef_$g.png $g 2>&1 | tail -4; done
cp /tmp/ef_1024.png $OUT/ 2>/dev/null; tar czf $OUT/runs.tgz -C /tmp/j .
export CI=true
for t in layouts tracer instances; do
  xz -dc .dev/carry/tm_$t.xz > /tmp/t_$t; chmod +x /tmp/t_$t
  timeout 100 /tmp/t_$t 2>&1 | grep -E "^test |test result|panicked|seed" | head -40
done
nvidia-smi --query-gpu=clocks.sm --format=csv
