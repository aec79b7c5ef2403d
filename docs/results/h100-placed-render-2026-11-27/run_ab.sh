# The bvh2 refit in one dispatch (treelet) against the build before this
# session's changes (treelet_base, 3617402), alternated three times; the
# render kernels of cornell and the disk-lit room, whose integrator gained
# one lookup for copies of meshes.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
for r in 1 2 3; do for bin in treelet_base treelet; do for sc in terrain:1000000 /tmp/bunny4.ply; do
  echo "== $bin bench dynamic $sc (round $r)"
  ./$bin bench dynamic --scene $sc --frames 7 --width 1920 --height 1080 2>&1 | grep -E "refit|closest hits|occlusion  |rror"
done; done; done
for r in 1 2; do for bin in treelet_base treelet; do
  echo "== $bin cornell 1024x768x1024 (round $r)"
  ./$bin render --scene cornell --width 1024 --height 768 --spp 1024 --device gpu --out /tmp/c.png 2>&1 | tail -1
  echo "== $bin room_disk 1024x768x256 (round $r)"
  ./$bin render --scene ../scenes/room_disk.json --width 1024 --height 768 --spp 256 --device gpu --out /tmp/r.png 2>&1 | tail -1
done; done
