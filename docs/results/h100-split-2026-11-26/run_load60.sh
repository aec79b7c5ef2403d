for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
/usr/bin/time -f "subdivide 7: %e s" python3 subdivide.py bunny.obj 7 bunny7.ply > /dev/null
for b in lbvh hploc; do echo "== build $b bunny7 (60.2M)"; /usr/bin/time -f "process %e s, %M KB" ./treelet build --builder $b --scene bunny7.ply 2>&1 | grep -vE "^device"; done
echo "== bench rays bunny7"; /usr/bin/time -f "process %e s, %M KB" ./treelet bench rays --scene bunny7.ply --mesh-only --accels lbvh,hploc --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | tail -6
echo "== treelet build --layout cwbvh? render 60M (expected: clear refusal)"; ./treelet bench rays --scene bunny7.ply --mesh-only --accels lbvh --layouts cwbvh --width 640 --height 480 --repeats 1 2>&1 | tail -2
