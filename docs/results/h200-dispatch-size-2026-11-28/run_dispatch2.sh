for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
R="--width 1024 --height 768 --device gpu"
ROOM=../scenes/room_disk.json
timeout -s KILL 60 ./treelet render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
for i in 1 2; do
 for m in 64 128 256 1024; do
  echo "== spp per dispatch $m"
  TREELET_MAX_SPP=$m TREELET_PATHS_PER_DISPATCH=4000000000 timeout -s KILL 60 ./treelet render $R --spp 1024 --out /tmp/c_$m.png 2>&1 | tail -1
  TREELET_MAX_SPP=$m TREELET_PATHS_PER_DISPATCH=4000000000 timeout -s KILL 60 ./treelet render --scene $ROOM $R --spp 1024 --out /tmp/r_$m.png 2>&1 | tail -1
  TREELET_MAX_SPP=$m TREELET_PATHS_PER_DISPATCH=4000000000 timeout -s KILL 60 ./treelet render --scene $ROOM $R --spp 1024 --integrator caustics --out /tmp/q_$m.png 2>&1 | tail -1
 done
done
TREELET_MAX_SPP=64 TREELET_PATHS_PER_DISPATCH=4000000000 timeout -s KILL 60 ./treelet render $R --width 1920 --height 1080 --spp 1024 --out /tmp/big64.png 2>&1 | tail -1
TREELET_MAX_SPP=256 TREELET_PATHS_PER_DISPATCH=4000000000 timeout -s KILL 60 ./treelet render $R --width 1920 --height 1080 --spp 1024 --out /tmp/big256.png 2>&1 | tail -1
timeout -s KILL 60 ./treelet render $R --width 1920 --height 1080 --spp 1024 --out /tmp/big.png 2>&1 | tail -1
timeout -s KILL 60 ./treelet render $R --width 256 --height 192 --spp 4096 --out /tmp/small.png 2>&1 | tail -1
TREELET_MAX_SPP=256 TREELET_PATHS_PER_DISPATCH=4000000000 timeout -s KILL 60 ./treelet render $R --width 256 --height 192 --spp 4096 --out /tmp/small256.png 2>&1 | tail -1
./treelet compare --help | head -5
