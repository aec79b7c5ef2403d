for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render $R --out /tmp/w.png 2>&1 | tail -1
for i in 1 2 3; do
 for b in treelet_old treelet; do
  echo "== $b"
  timeout -s KILL 60 ./$b render $R --out /tmp/c_$b.exr 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene $ROOM $R --out /tmp/r_$b.exr 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene $ROOM $R --integrator caustics --out /tmp/q_$b.exr 2>&1 | tail -1
 done
done
./treelet compare --reference /tmp/c_treelet_old.exr /tmp/c_treelet.exr
./treelet compare --reference /tmp/r_treelet_old.exr /tmp/r_treelet.exr
timeout -s KILL 60 ./treelet render $R --explain --out /tmp/x.png 2>&1 | tail -3
timeout -s KILL 60 ./treelet render --scene $ROOM $R --explain --out /tmp/x.png 2>&1 | tail -3
timeout -s KILL 60 ./treelet render --width 1920 --height 1080 --device gpu --spp 256 --scene $ROOM --explain --out /tmp/x.png 2>&1 | tail -2
cd ..
echo "== tests"
timeout 300 .dev/t_render --test-threads 4 2>&1 | tail -25
timeout 200 .dev/t_instances --test-threads 4 2>&1 | tail -6
