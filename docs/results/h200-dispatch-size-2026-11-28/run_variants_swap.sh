for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render $R --spp 1024 --out /tmp/w.png 2>&1 | tail -1
echo "== treelet_sized (f015b4a: 10 variants, the room on full) / treelet (spheres_shapes in, spheres_mirror and mixed_diffuse out)"
for i in 1 2 3; do
  for b in treelet_sized treelet; do
    echo "-- $b"
    timeout -s KILL 60 ./$b render --scene $ROOM $R --spp 1024 --out /tmp/r_$b.exr 2>&1 | tail -1
    timeout -s KILL 60 ./$b render --scene $ROOM $R --spp 1024 --integrator caustics --out /tmp/q_$b.exr 2>&1 | tail -1
    timeout -s KILL 60 ./$b render --scene ../scenes/cornell_mirrors.json $R --spp 1024 --out /tmp/m_$b.exr 2>&1 | tail -1
    timeout -s KILL 60 ./$b render --scene terrain:100000 $R --spp 64 --out /tmp/t_$b.exr 2>&1 | tail -1
    timeout -s KILL 60 ./$b render $R --spp 1024 --out /tmp/c_$b.exr 2>&1 | tail -1
  done
done
for s in r q m t c; do ./treelet compare --reference /tmp/${s}_treelet_sized.exr /tmp/${s}_treelet.exr; done
cd ..
echo "== tests"
for t in t_variants t_render t_devices t_instances; do timeout 250 .dev/$t --test-threads 4 2>&1 | grep -E "^test |test result|panicked|differ" | tail -20; done
