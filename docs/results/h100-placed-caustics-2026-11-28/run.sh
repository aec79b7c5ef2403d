for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
python3 subdivide.py bunny.obj 2 /tmp/bunny2.ply > /dev/null
python3 gen_room.py /tmp/bunny2.ply 256 /tmp/room_b2_256.json
R="--width 1024 --height 768 --device gpu"
./treelet render $R --spp 4 --scene /tmp/room_b2_256.json --integrator caustics --out /tmp/w.png >/dev/null 2>&1
./treelet_prev render $R --spp 4 --scene /tmp/room_b2_256.json --out /tmp/w.png >/dev/null 2>&1
for i in 1 2 3; do
  for t in treelet_prev treelet; do
    echo "== $t nee placed"; ./$t render $R --spp 64 --scene /tmp/room_b2_256.json --integrator nee --out /tmp/n_$t.pfm 2>&1 | tail -1
  done
  echo "== caustics placed"; ./treelet render $R --spp 64 --scene /tmp/room_b2_256.json --integrator caustics --out /tmp/c_placed.pfm 2>&1 | tail -1
done
./treelet render $R --spp 64 --scene /tmp/room_b2_256.json --integrator caustics --flatten --out /tmp/c_flat.pfm 2>&1 | tail -1
./treelet render $R --spp 64 --scene /tmp/room_b2_256.json --integrator caustics --flatten --seed 5 --out /tmp/c_flat5.pfm 2>&1 | tail -1
./treelet compare --reference /tmp/c_flat.pfm /tmp/c_placed.pfm
./treelet compare --reference /tmp/c_flat.pfm /tmp/c_flat5.pfm
./treelet compare --reference /tmp/n_treelet_prev.pfm /tmp/n_treelet.pfm
echo "== test instances"; ./instances --test-threads 4 2>&1 | grep -E "test result|FAILED|panicked|failed"
