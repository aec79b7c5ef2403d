for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
for l in 5 6 7; do /usr/bin/time -f "subdivide $l: %e s %M KB" python3 subdivide.py bunny.obj $l bunny$l.ply > /dev/null; done
ls -la *.ply
echo "== warm-up process (first run)"; ./treelet build --builder lbvh --scene bunny6.ply 2>&1 | tail -3
for l in 5 6; do
echo "== bench rays bunny$l"
./treelet bench rays --scene bunny$l.ply --mesh-only --accels lbvh,hploc --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5 2>&1
done
for b in lbvh hploc trbvh; do echo "== build $b bunny6"; ./treelet build --builder $b --scene bunny6.ply 2>&1 | grep -vE "^device"; done
echo "== bunny7 lbvh"; /usr/bin/time -f "%e s %M KB" ./treelet build --builder lbvh --scene bunny7.ply 2>&1 | tail -5
echo "== bunny7 rays"; ./treelet bench rays --scene bunny7.ply --mesh-only --accels lbvh --layouts bvh2 --width 1920 --height 1080 --repeats 3 2>&1 | tail -5
echo "== OptiX bunny6"; cd ..; python3 -c "import zipfile,glob; [zipfile.ZipFile(w).extractall('.whl/site') for w in glob.glob('.whl/*.whl')]"; PYTHONPATH=.whl/site timeout 200 python3 .whl/peer.py .dev/bunny6.ply 1920 1080 7 $OUT 2>&1 | grep -E "^\{" | head -2
