for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]" & cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
(python3 subdivide.py bunny.obj 5 bunny5.ply > /dev/null; /usr/bin/time -f "subdivide 7: %e s" python3 subdivide.py bunny.obj 7 bunny7.ply > /dev/null; echo "bunny7 made") &
echo "== treelet build (SAH, bunny4)"
for b in lbvh trbvh hploc; do ./treelet build --builder $b --device gpu --scene bunny4.ply | grep -E "device|builder|treelets|valid|time"; done
./treelet build --builder sweep --device cpu --scene bunny4.ply | grep -E "builder|time"
echo "== bench build (random spheres)"
./treelet bench build --builder trbvh --sizes 1000000,4000000,16000000 --repeats 7 2>&1 | tail -4
./treelet bench build --builder hploc --sizes 1000000,16000000 --repeats 7 2>&1 | tail -3
./treelet bench build --builder lbvh --sizes 1000000,16000000 --repeats 7 2>&1 | tail -3
echo "== bench rays bunny4, 1920x1080"
./treelet bench rays --scene bunny4.ply --mesh-only --accels lbvh,trbvh,hploc --layouts bvh2,cwbvh --width 1920 --height 1080
wait %1 2>/dev/null
echo "== OptiX bunny4"
(cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 150 python3 .whl/peer.py .dev/bunny4.ply 1920 1080 7 $OUT 2>&1 | grep '^{' | head -1)
while [ ! -f bunny5.ply ] || pgrep -f "subdivide.py bunny.obj 5" >/dev/null; do sleep 1; done
echo "== bench rays bunny5 (3.76M)"
./treelet bench rays --scene bunny5.ply --mesh-only --accels lbvh,trbvh,hploc --layouts bvh2 --width 1920 --height 1080 --repeats 5
echo "== OptiX bunny5"
(cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 150 python3 .whl/peer.py .dev/bunny5.ply 1920 1080 7 $OUT 2>&1 | grep '^{' | head -1)
wait
echo "== bench rays bunny7 (60.2M)"
/usr/bin/time -f "process %e s, %M KB" ./treelet bench rays --scene bunny7.ply --mesh-only --accels lbvh,hploc --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | tail -8
echo "== OptiX bunny7"
(cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 200 python3 .whl/peer.py .dev/bunny7.ply 1920 1080 5 $OUT 2>&1 | grep '^{' | head -1)
