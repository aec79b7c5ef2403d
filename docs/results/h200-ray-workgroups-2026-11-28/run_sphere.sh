for f in tb ta; do xz -dkf $f.xz; chmod +x $f; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv,noheader
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
./tb render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
for i in 1 2 3; do
 for b in tb ta; do
  echo "== $b round $i"
  timeout -s KILL 60 ./$b render $R --out /tmp/c_$b.png 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene $ROOM $R --out /tmp/r_$b.png 2>&1 | tail -1
 done
done
./tb compare --reference /tmp/c_tb.png /tmp/c_ta.png 2>&1 | tail -2
./tb compare --reference /tmp/r_tb.png /tmp/r_ta.png 2>&1 | tail -2
nvidia-smi --query-gpu=clocks.sm --format=csv,noheader
