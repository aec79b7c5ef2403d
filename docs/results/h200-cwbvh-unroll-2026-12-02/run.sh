#!/usr/bin/env bash
# K (main) against M (cwbvh hit_bits written out per child, branch wip/cwbvh-unroll).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet_k.xz > /tmp/K; xz -dc .dev/carry/treelet_m.xz > /tmp/M; chmod +x /tmp/K /tmp/M
c="--width 1920 --height 1080 --repeats 5"
for r in K1 M1 M2 K2; do
  s=$(date +%s)
  timeout 60 /tmp/${r:0:1} bench rays --suite --accels trbvh --layouts bvh2,cwbvh $c --json $OUT/$r.json > /tmp/$r.log 2>&1
  echo "$r rc=$? $(( $(date +%s) - s ))s"
done
for v in E M; do xz -dc .dev/carry/ps_$v.xz > /tmp/ps_$v; chmod +x /tmp/ps_$v; timeout 60 /tmp/ps_$v render::cast_bvh2_triangles_cs render::cast_cwbvh_triangles_cs render::cast_cwbvh_cs > /tmp/ps_$v.txt 2>&1; echo "== $v"; cat /tmp/ps_$v.txt | tail -8; done
nvidia-smi --query-gpu=clocks.sm --format=csv
