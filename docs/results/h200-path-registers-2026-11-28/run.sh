for f in tn tp pipeline_stats; do xz -dkf $f.xz; chmod +x $f; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv,noheader
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
./tn render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
for i in 1 2 3; do
 for b in tn tp; do
  echo "== $b round $i"
  timeout -s KILL 60 ./$b render $R --out /tmp/c_$b.pfm 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene $ROOM $R --out /tmp/r_$b.pfm 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene bunny.obj --width 1024 --height 768 --device gpu --spp 256 --out /tmp/b_$b.pfm 2>&1 | tail -1
 done
done
for s in c r b; do ./tn compare --reference /tmp/${s}_tn.pfm /tmp/${s}_tp.pfm 2>&1 | tail -1; done
./pipeline_stats render::spheres::linear_cs render::spheres_shapes::linear_cs render::mixed_diffuse::bvh2_cs render::render_placed_cs 2>&1 | tail -4
nvidia-smi --query-gpu=clocks.sm --format=csv,noheader
