#!/usr/bin/env bash
# Two measurements for one call (carry .gl, .whl, .dev/carry/treelet.xz: the release binary of
# main, stripped; .dev/carry/bunny.obj: the npm package `bunny`'s 3 674 triangles as OBJ):
# 1. Issue 63: 1 024 turned copies of the 940k bunny, Treelet (`bench instances`) and OptiX
#    (peers/mitsuba/instances.py) alternately, twice.
# 2. Issue 66: mesh loads on this host (`bench load`), PLY and OBJ of 1M and 10M triangles and a
#    50M-triangle PLY, on all cores and on two (taskset), beside `read` and `cat`.
# 3. Issue 67: the Python wheel of 337439a (.dev/carry/pyw_new2.tar.xz: fresh hit arrays zeroed on
#    every core) through python/examples/bench_rays.py, twice a mesh, the second with Mitsuba 3.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
nproc; free -g | head -2; df -h /tmp | tail -1
xz -dc .dev/carry/treelet.xz > /tmp/treelet; chmod +x /tmp/treelet
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
for round in 1 2; do
  echo "== treelet bench instances bunny4 32x32, round $round"
  timeout 150 /tmp/treelet bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000,100000 --repeats 7 --json $OUT/instances_bunny4_$round.json 2>&1 | grep -v "^\s*$" | tail -8
  echo "== OptiX instances bunny4 32x32, round $round"
  (cd peers/mitsuba && PYTHONPATH=/tmp/site PYTHONUNBUFFERED=1 timeout 150 python3 instances.py /tmp/bunny4.ply 32 1920 1080 7 2>&1 | tail -6)
done
nvidia-smi --query-gpu=clocks.sm --format=csv
echo "== bench load, all cores"
timeout 200 /tmp/treelet bench load --sizes 1000000,10000000 --dir /tmp/bl --repeats 5 2>&1 | grep -v "^writing" | tail -5
timeout 100 /tmp/treelet export --scene terrain:50000000 --out /tmp/bl/terrain_50000000.ply 2>&1 | tail -1
timeout 100 /tmp/treelet bench load /tmp/bl/terrain_50000000.ply --repeats 3 2>&1 | tail -1
echo "== bench load, two cores (taskset -c 0,1)"
timeout 200 taskset -c 0,1 /tmp/treelet bench load /tmp/bl/terrain_1000000.ply /tmp/bl/terrain_1000000.obj /tmp/bl/terrain_10000000.ply /tmp/bl/terrain_10000000.obj /tmp/bl/terrain_50000000.ply --repeats 3 2>&1 | tail -6
echo "== Python (337439a)"
mkdir -p /tmp/pyw_new2 && tar xJf .dev/carry/pyw_new2.tar.xz -C /tmp/pyw_new2
python3 - <<'PY'
import numpy as np
n = 708  # 2 * 707 * 707 = 999 698 triangles
x, y = np.meshgrid(np.linspace(0, 100, n), np.linspace(0, 100, n))
z = 3 * np.sin(x * 0.3) * np.cos(y * 0.2) + np.random.default_rng(2).normal(0, 0.05, x.shape)
v = np.stack([x, y, z], -1).reshape(-1, 3).astype("<f4")
i = np.arange(n * n).reshape(n, n)
a, b, c, d = i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(), i[1:, :-1].ravel()
f = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype("<i4")
head = f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\nelement face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n"
rec = np.zeros(len(f), dtype=np.dtype([("n", "u1"), ("i", "<i4", 3)])); rec["n"] = 3; rec["i"] = f
open("/tmp/field.ply", "wb").write(head.encode() + v.tobytes() + rec.tobytes())
PY
for mesh in scenes/real/breakfast_room.ply.xz scenes/real/staircase.ply.xz /tmp/field.ply; do
  for k in 1 2; do
    echo "== $mesh new2:$k"
    PYTHONPATH=/tmp/pyw_new2:/tmp/site timeout 100 python3 python/examples/bench_rays.py $mesh --rays 1000000 --device gpu --repeats 9 $([ $k = 2 ] && echo --mitsuba) 2>&1 | grep -v "^$" | tail -6
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
