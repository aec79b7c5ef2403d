for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu"
for T in ./treelet_before ./treelet; do timeout -s KILL 60 $T render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1; done
echo "== cornell nee 1024 spp: c428c28 (before light paths) / now (light-path logic only in the caustics variants), interleaved"
for i in 1 2 3; do for T in ./treelet_before ./treelet; do echo -n "$T: "; timeout -s KILL 60 $T render $R --spp 1024 --seed 3 --out /tmp/c_${T#./}.png 2>&1 | tail -1; done; done
cmp /tmp/c_treelet_before.png /tmp/c_treelet.png && echo "cornell nee: before and now identical"
echo "== room nee and caustics"
for i in 1 2; do for T in ./treelet_before ./treelet; do echo -n "$T: "; timeout -s KILL 60 $T render --scene ../scenes/room_disk.json $R --spp 1024 --seed 3 --out /tmp/r_${T#./}.png 2>&1 | tail -1; done; done
cmp /tmp/r_treelet_before.png /tmp/r_treelet.png && echo "room nee: before and now identical"
for i in 1 2; do for T in ./treelet; do echo -n "$T: "; timeout -s KILL 60 $T render --scene ../scenes/room_disk.json $R --integrator caustics --spp 1024 --out /tmp/r.png 2>&1 | tail -1; done; done
echo "== explain"; ./treelet render --scene ../scenes/room_disk.json $R --integrator caustics --spp 16 --explain --out /tmp/x.png 2>&1 | grep -E "^kernel|integrator"
