for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
echo "== bench build lbvh/hploc (regression check)"; for b in lbvh hploc; do ./treelet bench build --builder $b --sizes 1000000,16000000 --repeats 11 2>&1 | tail -2; done
echo "== rays bunny4 (unchanged traversal)"; ./treelet bench rays --scene bunny4.ply --mesh-only --accels lbvh,hploc --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | tail -3
/usr/bin/time -f "subdivide 7: %e s" python3 subdivide.py bunny.obj 7 bunny7.ply > /dev/null
for b in lbvh hploc; do echo "== build $b bunny7 (60.2M)"; /usr/bin/time -f "process %e s, %M KB" ./treelet build --builder $b --scene bunny7.ply 2>&1 | grep -vE "^device"; done
echo "== rays bunny7"; ./treelet bench rays --scene bunny7.ply --mesh-only --accels lbvh --layouts bvh2 --width 1920 --height 1080 --repeats 3 2>&1 | tail -4
