#!/usr/bin/env bash
# Python's hits written on every core (401a468) against the wheel before (b572331: one core), old
# and new alternately, with the Rust API's times from each wheel and Mitsuba 3 (OptiX) beside:
# python/examples/bench_rays.py, 1M incoherent rays, two meshes of the suite and a 1M-triangle
# height field (made as in ../h200-python-batches-2026-12-02/run.sh).
# Carry: .gl, .whl (Mitsuba 3's site), .dev/carry/pyw_old.tar.xz and pyw_new.tar.xz (the wheels' files).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
nproc; free -g | head -2
for w in old new; do mkdir -p /tmp/pyw_$w && tar xJf .dev/carry/pyw_$w.tar.xz -C /tmp/pyw_$w; done
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
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
  for k in old:1 new:1 old:2 new:2; do
    w=${k%:*}
    echo "== $mesh $k"
    PYTHONPATH=/tmp/pyw_$w:/tmp/site timeout 100 python3 python/examples/bench_rays.py $mesh --rays 1000000 --device gpu --repeats 9 $([ $k = new:2 ] && echo --mitsuba) 2>&1 | grep -v "^$" | tail -6
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
