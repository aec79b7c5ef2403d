#!/usr/bin/env bash
# Where main stands on the H200 (2026-12-05), in up to three calls (the carry limit keeps Mitsuba's
# site, 25 MB, out of the last):
#   run.sh suite   : the real-scene suite with OptiX beside (carry .gl, .whl, .dev/carry/treelet.xz)
#   run.sh python  : issue 67's benchmark, 1M rays against the 940k bunny, NumPy in and out, the
#                    Rust API inside the module and Mitsuba 3 (carry .gl, .whl, .dev/carry/pyw.tar.xz,
#                    .dev/carry/bunny.obj: the npm package `bunny` as OBJ)
#   run.sh engine  : the engine example's frames on the H200 (carry .gl, .dev/carry/engine_frames.xz)
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv,noheader
[ -f .whl/site.tar.xz ] && (cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)
case $1 in
  suite)
    xz -dc .dev/carry/treelet.xz > /tmp/T; chmod +x /tmp/T
    PYTHONPATH=/tmp/site timeout 300 /tmp/T bench rays --suite --with-optix --accels trbvh,hploc --layouts bvh2,cwbvh \
      --width 1920 --height 1080 --repeats 5 --json $OUT/suite.json > $OUT/suite.txt 2>&1; echo "suite rc=$?"
    tail -40 $OUT/suite.txt ;;
  python)
    python3 peers/meshes/subdivide.py .dev/carry/bunny.obj 4 /tmp/bunny4.ply
    mkdir -p /tmp/pyw && tar xJf .dev/carry/pyw.tar.xz -C /tmp/pyw
    for k in 1 2 3; do
      echo "== round $k"
      PYTHONPATH=/tmp/pyw:/tmp/site timeout 100 python3 python/examples/bench_rays.py /tmp/bunny4.ply --rays 1000000 --device gpu --repeats 9 $([ $k = 3 ] && echo --mitsuba) 2>&1 | grep -v "^$" | tail -8
    done 2>&1 | tee $OUT/python.txt ;;
  engine)
    xz -dc .dev/carry/engine_frames.xz > /tmp/E; chmod +x /tmp/E
    (cd $OUT && timeout 120 /tmp/E 60 engine_frames.png) 2>&1 | tee $OUT/engine.txt ;;
esac
nvidia-smi --query-gpu=clocks.sm --format=csv,noheader
