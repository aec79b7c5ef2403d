# Process time before (treelet_before, 03a830a) and after (treelet) this
# session's start-up work, interleaved on one H100; cornell, the disk-lit
# room, and the bunny subdivided to 940 544 triangles.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
R="--width 1024 --height 768"
for T in ./treelet_before ./treelet; do $T render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1; done
one() { # binary, label, args...
  T=$1; L=$2; shift 2
  /usr/bin/time -f "wall %e" $T render $R "$@" --explain --out /tmp/o.png 2>&1 | grep -E "^timeline|M camera paths|^wall" \
    | sed -e 's/(the stages.*//' -e 's/.*M camera paths\/s; //' -e 's/), wrote.*//' | tr '\n' ' ' | sed "s|^|$L $T |"; echo
}
for i in 1 2 3 4 5; do for T in ./treelet_before ./treelet; do
  one $T cornell --spp 1024
  one $T room --scene ../scenes/room_disk.json --spp 256
  one $T bunny --scene /tmp/bunny4.ply --spp 64
done; done
