for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
for i in 1 2; do
 for p in 4194304 8388608 16777216 33554432 67108864; do
  echo "== paths per dispatch $p"
  TREELET_PATHS_PER_DISPATCH=$p timeout -s KILL 60 ./treelet render $R --spp 1024 --out /tmp/c_$p.png 2>&1 | tail -1
  TREELET_PATHS_PER_DISPATCH=$p timeout -s KILL 60 ./treelet render --scene $ROOM $R --spp 1024 --out /tmp/r_$p.png 2>&1 | tail -1
 done
done
./treelet compare /tmp/c_4194304.png /tmp/c_67108864.png 2>&1 | tail -2
TREELET_PATHS_PER_DISPATCH=67108864 timeout -s KILL 60 ./treelet render $R --spp 1024 --explain --out /tmp/x.png 2>&1 | tail -30
