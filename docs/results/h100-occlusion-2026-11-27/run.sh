# Occlusion queries against closest hits through the engine API on the
# H100: bench dynamic's frame rays and their cosine bounces (diffuse,
# unbounded; ambient occlusion, 5% of the extent), and bench rays' diffuse
# rays in smallpt's room (the same cast kernel's occlusion mode).
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
for sc in terrain:1000000 /tmp/bunny4.ply; do
  echo "== bench dynamic $sc"
  ./treelet bench dynamic --scene $sc --frames 5 --width 1920 --height 1080 --json /tmp/d.json 2>&1 | tail -8
  cp /tmp/d.json $OUT/dynamic_$(basename $sc | tr ':' '_').json
done
echo "== bench rays bunny4 in the room"
./treelet bench rays --scene /tmp/bunny4.ply --accels trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 7 2>&1 | tail -6
echo "== bench rays bunny4 mesh only"
./treelet bench rays --scene /tmp/bunny4.ply --accels trbvh --layouts bvh2 --width 1920 --height 1080 --repeats 7 --mesh-only 2>&1 | tail -3
