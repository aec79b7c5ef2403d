for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]" & cd .dev
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
echo "== treelet build (SAH, bunny4)"
for b in lbvh trbvh hploc; do ./treelet build --builder $b --device gpu --scene bunny4.ply | grep -E "device|builder|treelets|valid|time"; done
./treelet build --builder sweep --device cpu --scene bunny4.ply | grep -E "builder"
echo "== bench build (random spheres)"
./treelet bench build --builder hploc --sizes 16000000,65536,1000000,4000000 --repeats 21
./treelet bench build --builder lbvh --sizes 16000000,65536,1000000,4000000 --repeats 21
./treelet bench build --builder trbvh --sizes 1000000,4000000 --repeats 11
echo "== bench rays bunny4, 1920x1080"
./treelet bench rays --scene bunny4.ply --mesh-only --accels lbvh,trbvh,hploc --layouts bvh2,cwbvh --width 1920 --height 1080
wait
echo "== OptiX (Mitsuba 3) on bunny4, same call"
cd ..; PYTHONPATH=.whl/site PYTHONUNBUFFERED=1 timeout 200 python3 .whl/peer.py .dev/bunny4.ply 1920 1080 7 $OUT 2>&1 | grep '^{' | head -5
