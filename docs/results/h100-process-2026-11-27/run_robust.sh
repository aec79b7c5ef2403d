# Robust buffer access (wgpu turns it on) against off (this build's default),
# alternated on one H100: render kernels, rays, builds.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
[ -f /tmp/bunny4.ply ] || python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
R="--width 1024 --height 768"
for i in 1 2 3; do for rb in 1 0; do
  export TREELET_ROBUST_BUFFERS=$rb
  echo "-- robust=$rb round $i"
  ./treelet render $R --spp 1024 --out /tmp/c$rb.exr 2>&1 | tail -1 | sed 's/.*M camera/cornell: M camera/'
  ./treelet render $R --spp 256 --scene ../scenes/room_disk.json --out /tmp/r$rb.exr 2>&1 | tail -1 | sed 's/.*M camera/room: M camera/'
  ./treelet render $R --spp 64 --scene /tmp/bunny4.ply --out /tmp/b$rb.exr 2>&1 | tail -1 | sed 's/.*M camera/bunny4: M camera/'
  ./treelet bench rays --scene /tmp/bunny4.ply --mesh-only --accels trbvh --layouts bvh2,cwbvh --width 1920 --height 1080 --repeats 5 2>&1 | grep -E "^ trbvh"
  ./treelet bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -1
  ./treelet bench build --builder lbvh --sizes 1000000 --repeats 7 2>&1 | tail -1
done; done
unset TREELET_ROBUST_BUFFERS
for s in c r b; do ./treelet compare /tmp/${s}0.exr --reference /tmp/${s}1.exr; done
