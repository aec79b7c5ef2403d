#!/usr/bin/env bash
# The engine API's host batches (issues 64, 67): rays written straight into kept upload memory and
# hits read from kept read-back memory (`closest_hits_with`), against the wheel of main before it
# (c3560e7), alternately in one call (old, new, old, new), then Mitsuba 3 (OptiX) from Python on the
# same rays; new is 76168b5 in log_h200.txt, 2948445 (parallel chunked uploads) in log_h200_2.txt and the next commit (timings that drop the last result first, hits into a kept buffer) in log_h200_3.txt, 97c7574 (hit arrays mapped in at once, pushed) in log_h200_4.txt. 1M incoherent rays, three meshes: two real scenes of the suite and a 1M-triangle height field.
# Carry: .gl (the Vulkan loader's debs), .whl (Mitsuba 3's site, slimmed), .dev/py (pytest's wheels),
# .dev/wheels.tar.xz (the two wheels' files).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
# The two wheels' files, unpacked (new/, old/) and packed in one xz archive (they share most bytes).
(cd /tmp && tar xJf $OLDPWD/.dev/wheels.tar.xz && mv new py_new && mv old py_old)
for w in .dev/py/*.whl; do (cd /tmp/py_new && python3 -m zipfile -e $OLDPWD/$w .); done
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
(cd /tmp && CI=true PYTEST_DISABLE_PLUGIN_AUTOLOAD=1 PYTHONPATH=/tmp/py_new timeout 200 python3 -m pytest -q -p no:cacheprovider $OLDPWD/python/tests 2>&1 | tail -3)
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
print("height field:", len(f), "triangles")
PY
for mesh in scenes/real/breakfast_room.ply.xz scenes/real/staircase.ply.xz /tmp/field.ply; do
  for v in old new old new; do
    extra=""; [ $v = new ] && extra="--mitsuba"
    echo "== $mesh $v"
    PYTHONPATH=/tmp/py_$v:/tmp/site timeout 100 python3 python/examples/bench_rays.py $mesh --rays 1000000 --device gpu --repeats 7 $extra 2>&1 | grep -v "^$" | tail -6
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
