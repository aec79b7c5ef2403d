#!/usr/bin/env bash
# Issue 67's benchmark on its own mesh: 1M incoherent rays against the 940k bunny (the npm package
# `bunny`, .dev/carry/bunny.obj, subdivided four times), NumPy in and NumPy hits out, with the wheel
# of b69e0d5 (.dev/carry/pyw_b69.tar.xz, unpacked), against the Rust API's time inside the module
# and Mitsuba 3 (OptiX), three rounds (Mitsuba in the second and third).
# Second call (run.sh fresh): the same with the wheel that writes fresh arrays without zeroing them
# first (.dev/carry/pyw_fresh.tar.xz) and b69e0d5's alternately, three rounds each.
# Carry: .gl, .whl, .dev/carry/pyw_b69.tar.xz, .dev/carry/pyw_fresh.tar.xz, .dev/carry/bunny.obj.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
nproc
python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
if [ "$1" = fresh ]; then wheels="b69 fresh"; else wheels="b69"; fi
for w in $wheels; do mkdir -p /tmp/pyw_$w && tar xJf .dev/carry/pyw_$w.tar.xz -C /tmp/pyw_$w; done
for k in 1 2 3; do
  for w in $wheels; do
    echo "== bunny4, wheel $w, round $k"
    PYTHONPATH=/tmp/pyw_$w:/tmp/site timeout 100 python3 python/examples/bench_rays.py /tmp/bunny4.ply --rays 1000000 --device gpu --repeats 9 $([ $k != 1 ] && [ $w = b69 ] && echo --mitsuba) 2>&1 | grep -v "^$" | tail -6
  done
done
nvidia-smi --query-gpu=clocks.sm --format=csv
