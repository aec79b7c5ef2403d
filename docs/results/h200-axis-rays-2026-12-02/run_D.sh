#!/usr/bin/env bash
# A (main) against E (ties reached: t_max widened per node and per pop) and
# D (E, and parallel axes bounded by the root box, loaded for every ray).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_e.xz > /tmp/A; xz -dc .dev/carry/treelet_h.xz > /tmp/E; xz -dc .dev/carry/treelet_i.xz > /tmp/D; chmod +x /tmp/A /tmp/E /tmp/D
c="--width 1920 --height 1080 --repeats 5"
for r in A1 E1 D1 D2 E2 A2; do
  s=$(date +%s)
  timeout 60 /tmp/${r:0:1} bench rays --suite --accels trbvh --layouts bvh2,cwbvh $c --json $OUT/$r.json > $OUT/$r.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"
done
for v in E D; do xz -dc .dev/carry/ps_$v.xz > /tmp/ps_$v; chmod +x /tmp/ps_$v; timeout 60 /tmp/ps_$v render::cast_bvh2_triangles_cs render::cast_bvh2_cs render::cast_cwbvh_triangles_cs render::cast_instances_cs > $OUT/ps_$v.txt 2>&1; cat $OUT/ps_$v.txt; done
nvidia-smi --query-gpu=clocks.sm --format=csv
