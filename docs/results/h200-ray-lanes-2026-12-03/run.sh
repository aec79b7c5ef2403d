#!/usr/bin/env bash
# Diffuse rays on a fixed number of lanes, each taking every N-th ray in one
# walk loop (TREELET_RAY_LANES=N), against one lane a ray (N=0), alternately
# in one call, on the real-scene suite (binary N: main at this commit).
# First, every committed entry point's pipeline is created in a process of
# its own (the cast kernels crashed NVIDIA's compiler: ../h200-cast-crash-2026-12-03/).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_n.xz > /tmp/N; chmod +x /tmp/N
xz -dc .dev/carry/ps.xz > /tmp/ps; chmod +x /tmp/ps
while read e; do timeout 60 /tmp/ps $e > /tmp/one.log 2>&1; rc=$?; echo "$rc $e $(tail -1 /tmp/one.log | cut -c1-150)"; done < .dev/carry/entries.txt > $OUT/pipelines.txt
echo "pipelines: $(grep -c '^0 ' $OUT/pipelines.txt) compiled, failed: $(grep -v '^0 ' $OUT/pipelines.txt | cut -c1-60 | tr '\n' ';')"
for f in .dev/x/*.spv; do timeout 60 /tmp/ps $f > /tmp/one.log 2>&1; echo "$? $f"; done
timeout 60 /tmp/N bench rays --scene terrain:10000 --mesh-only --accels trbvh --layouts bvh2,cwbvh --width 256 --height 256 --repeats 1 > $OUT/quick.log 2>&1; echo "quick rc=$?"; tail -3 $OUT/quick.log
c="--suite --accels trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5"
run() {
  IFS=: read bin lanes k <<< "$1"
  s=$(date +%s)
  TREELET_RAY_LANES=$lanes timeout 100 /tmp/$bin bench rays $c $2 --json $OUT/${bin}_${lanes}_$k.json > $OUT/${bin}_${lanes}_$k.log 2>&1
  echo "$1 $2 rc=$? $(( $(date +%s) - s ))s"
}
for r in N:0:1 N:262144:1 N:131072:1 N:0:2; do run $r; done
# OptiX (Mitsuba 3, peers/mitsuba/rays.py) beside, one more run of the suite on 262144 lanes.
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
export PYTHONPATH=/tmp/site; run N:262144:optix --with-optix
mv $OUT/N_262144_optix.json $OUT/optix.json; mv $OUT/N_262144_optix.log $OUT/optix.log
run N:524288:1
nvidia-smi --query-gpu=clocks.sm --format=csv
