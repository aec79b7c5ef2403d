#!/usr/bin/env bash
# Bisecting the instanced grid's primary-ray regression (../h200-instances-load-2026-12-03/):
# `bench instances` on the 940k bunny with release binaries of f950f92, 4bd6eff, 1824a40, 779c44d,
# 9a601e4 and 337439a (.dev/carry/bin_*.xz, treelet.xz), f950f92 and 337439a again at the end.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply
for c in f950f92 4bd6eff 1824a40 779c44d 9a601e4; do xz -dc .dev/carry/bin_$c.xz > /tmp/bin_$c; chmod +x /tmp/bin_$c; done
xz -dc .dev/carry/treelet.xz > /tmp/bin_337439a; chmod +x /tmp/bin_337439a
for c in f950f92 337439a 4bd6eff 1824a40 779c44d 9a601e4 f950f92 337439a; do
  echo "== $c"
  timeout 90 /tmp/bin_$c bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 5 2>&1 | grep -E "mesh alone|in place|copies|above"
done
nvidia-smi --query-gpu=clocks.sm --format=csv
