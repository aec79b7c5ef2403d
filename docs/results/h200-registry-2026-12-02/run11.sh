#!/usr/bin/env bash
# The kernel registry on the H200: GPU-vs-CPU tests, then the suite through every builder with the
# registry's binary (D) against the shipped one (A).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export CI=true
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv
for t in gpu_vs_cpu layouts treelet instances tracer; do
  xz -dc .dev/carry/t_$t.xz > /tmp/$t; chmod +x /tmp/$t
  echo "== $t"; timeout 150 /tmp/$t 2>&1 | grep -E "^test result|FAILED|panicked|adapter" | head -8
done
xz -dc .dev/carry/treelet_a.xz > /tmp/A; xz -dc .dev/carry/treelet_d.xz > /tmp/D; chmod +x /tmp/A /tmp/D
c="--width 1920 --height 1080 --repeats 3"
for r in A D; do
  echo "== $r suite"
  timeout 100 /tmp/$r bench rays --suite --accels lbvh,trbvh,hploc --layouts bvh2,cwbvh $c 2>&1 | grep -E "^ +(breakfast|staircase|city:1000000)" | head -40
done
echo "== render default"; timeout 60 /tmp/D render --spp 16 --out /tmp/d.png 2>&1 | tail -2
echo "== build json"; for dev in gpu cpu; do timeout 60 /tmp/D build --scene scenes/real/classroom.ply.xz --builder trbvh --device $dev --json 2>/dev/null | python3 -c "import json,sys; d=json.load(sys.stdin); print('$dev', {k: d.get(k) for k in ('sah_cost','epo','references','nodes','valid','adapter')})"; done
