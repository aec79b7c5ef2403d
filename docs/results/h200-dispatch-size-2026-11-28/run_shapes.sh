for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render $R --out /tmp/w.png 2>&1 | tail -1
echo "== the room: treelet_sized (f015b4a, full kernel) / treelet (spheres_shapes) / treelet --kernel full"
for i in 1 2 3; do
  for b in treelet_sized treelet; do
    echo "-- $b"
    timeout -s KILL 60 ./$b render --scene $ROOM $R --out /tmp/r_$b.exr 2>&1 | tail -1
    timeout -s KILL 60 ./$b render --scene $ROOM $R --integrator caustics --out /tmp/q_$b.exr 2>&1 | tail -1
  done
  echo "-- treelet --kernel full"
  timeout -s KILL 60 ./treelet render --scene $ROOM $R --kernel full --out /tmp/rf.exr 2>&1 | tail -1
  timeout -s KILL 60 ./treelet render --scene $ROOM $R --kernel full --integrator caustics --out /tmp/qf.exr 2>&1 | tail -1
  echo "-- cornell"
  timeout -s KILL 60 ./treelet render $R --out /tmp/c.exr 2>&1 | tail -1
done
for s in r q; do ./treelet compare --reference /tmp/${s}_treelet_sized.exr /tmp/${s}_treelet.exr; done
./treelet compare --reference /tmp/rf.exr /tmp/r_treelet.exr
echo "== registers"
./pipeline_stats 2>&1 | grep -E "render::(spheres_shapes|full|spheres)::linear|render::(spheres_shapes_caustics|full_caustics)::linear|light::" | head -20
cd ..
echo "== tests"
for t in t_variants t_render t_devices; do timeout 250 .dev/$t --test-threads 4 2>&1 | grep -E "^test |test result|panicked|differ" | tail -20; done
