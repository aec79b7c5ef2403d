for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render $R --out /tmp/w.png 2>&1 | tail -1
timeout -s KILL 60 ./treelet_new render $R --out /tmp/w.png 2>&1 | tail -1
for i in 1 2 3; do
 for b in treelet treelet_new; do
  echo "== $b"
  timeout -s KILL 60 ./$b render $R --out /tmp/c_$b.exr 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene $ROOM $R --out /tmp/r_$b.exr 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene $ROOM $R --integrator caustics --out /tmp/q_$b.exr 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --device gpu --out /tmp/d_$b.png 2>&1 | tail -1
 done
done
./treelet compare --reference /tmp/c_treelet.exr /tmp/c_treelet_new.exr
./treelet compare --reference /tmp/r_treelet.exr /tmp/r_treelet_new.exr
./treelet compare --reference /tmp/q_treelet.exr /tmp/q_treelet_new.exr
for b in treelet treelet_new; do
timeout -s KILL 60 ./$b render $R --explain --out /tmp/x.png 2>&1 | grep -E "^(timeline|dispatches)|camera paths"
timeout -s KILL 60 ./$b render --device gpu --explain --out /tmp/x.png 2>&1 | grep -E "^(timeline|dispatches)|camera paths"
done
cd ..
echo "== tests"
timeout 300 .dev/t_render --test-threads 4 2>&1 | grep -E "^test |test result|dispatch|seed"
