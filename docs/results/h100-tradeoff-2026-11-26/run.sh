for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
mkdir -p res
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
python3 subdivide.py bunny.obj 5 bunny5.ply > /dev/null
cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]"; cd .dev
# warm-up process (pipelines, clocks)
./treelet bench rays --scene bunny4.ply --mesh-only --accels lbvh --layouts bvh2 --width 640 --height 480 --repeats 3 > /dev/null 2>&1
for m in bunny4 bunny5; do
  echo "== OptiX $m"; (cd ..; mkdir -p /tmp/peer; PYTHONPATH=.whl/site timeout 240 python3 .whl/peer.py .dev/$m.ply 1920 1080 7 /tmp/peer 2>&1 | grep -E "^\{" | head -1) | tee optix_$m.jsonl
  echo "== treelet $m"; ./treelet bench rays --scene $m.ply --mesh-only --accels lbvh,hploc,trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 7 --json res/rays_$m.json --figure res/fig_$m --optix optix_$m.jsonl 2>&1 | grep -v "layout of the"
done
cp optix_*.jsonl res/; tar cf $OUT/res.tar res
