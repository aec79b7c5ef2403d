# Memory blocks: wgpu's Performance hint (treelet_before) against blocks from
# 8 MiB (host 4 MiB) growing to 256 MiB (treelet), interleaved on one H100.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
[ -f /tmp/bunny4.ply ] || python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
R="--width 1024 --height 768"
for T in ./treelet_before ./treelet; do $T render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1; done
for i in 1 2 3 4 5; do for T in ./treelet_before ./treelet; do
  echo "$T cornell $($T render $R --spp 1024 --out /tmp/c.png 2>&1 | tail -1 | sed -e 's/.*M camera paths\/s; //' -e 's/), wrote.*//')" | sed "s|./treelet render|$T|"
done; done 2>&1 | sed 's/^\(\S*\) cornell/\1 cornell/'
for i in 1 2 3; do for T in ./treelet_before ./treelet; do
  echo "$T room $($T render $R --spp 256 --scene ../scenes/room_disk.json --out /tmp/r.png 2>&1 | tail -1 | sed -e 's/.*M camera paths\/s; //' -e 's/), wrote.*//')"
  echo "$T bunny $($T render $R --spp 64 --scene /tmp/bunny4.ply --out /tmp/b.png 2>&1 | tail -1 | sed -e 's/.*M camera paths\/s; //' -e 's/), wrote.*//')"
  echo "$T rays $($T bench rays --scene /tmp/bunny4.ply --mesh-only --accels trbvh --layouts bvh2 --width 1920 --height 1080 --repeats 5 2>&1 | grep -E '^ trbvh')"
  echo "$T build $($T bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -1)"
done; done
