# Light paths through placed copies: the placed kernel's time with NEE
# before (treelet_prev) and after (treelet: CAUSTICS compiled in), and
# caustics through copies against caustics flattened.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 2 /tmp/bunny2.ply > /dev/null
python3 gen_room.py /tmp/bunny2.ply 256 /tmp/room_b2_256.json
R="--width 1024 --height 768 --device gpu"
./treelet render $R --spp 4 --scene /tmp/room_b2_256.json --integrator caustics --out /tmp/w.png >/dev/null 2>&1
./treelet_prev render $R --spp 4 --scene /tmp/room_b2_256.json --out /tmp/w.png >/dev/null 2>&1
./treelet render $R --spp 4 --scene /tmp/room_b2_256.json --integrator caustics --flatten --out /tmp/w.png >/dev/null 2>&1
for i in 1 2 3; do
  for t in treelet_prev treelet; do
    echo "== $t nee placed"; ./$t render $R --spp 64 --scene /tmp/room_b2_256.json --integrator nee --out /tmp/n_$t.pfm 2>&1 | tail -1
  done
done
for i in 1 2; do
  echo "== caustics placed"; ./treelet render $R --spp 64 --scene /tmp/room_b2_256.json --integrator caustics --out /tmp/c_placed.pfm 2>&1 | tail -1
  echo "== caustics flattened"; ./treelet render $R --spp 64 --scene /tmp/room_b2_256.json --integrator caustics --flatten --out /tmp/c_flat.pfm 2>&1 | tail -1
done
./treelet compare --reference /tmp/c_flat.pfm /tmp/c_placed.pfm
./treelet compare --reference /tmp/n_treelet_prev.pfm /tmp/n_treelet.pfm
echo "== auto on the placed room"; ./treelet render $R --spp 1024 --scene /tmp/room_b2_256.json --integrator auto --explain --out /tmp/a.png 2>&1 | grep -E "integrator|room_b2" | tail -3
echo "== pyramids"; for g in nee caustics; do ./treelet render $R --spp 256 --scene ../scenes/pyramids.json --integrator $g --out $OUT/pyramids_$g.png 2>&1 | tail -1; done
