for f in tb tn; do xz -dkf $f.xz; chmod +x $f; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv,noheader
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
R="--width 1024 --height 768 --device gpu --spp 1024"
ROOM=../scenes/room_disk.json
./tb render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
for i in 1 2; do
 for b in tb tn; do
  echo "== $b round $i"
  timeout -s KILL 60 ./$b render $R --out /tmp/c_$b.pfm 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene $ROOM $R --out /tmp/r_$b.pfm 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene bunny.obj --width 1024 --height 768 --device gpu --spp 256 --out /tmp/b_$b.pfm 2>&1 | tail -1
  timeout -s KILL 60 ./$b render --scene $ROOM $R --integrator caustics --out /tmp/l_$b.pfm 2>&1 | tail -1
  timeout -s KILL 120 ./$b bench rays --scene /tmp/bunny4.ply --mesh-only --repeats 5 2>&1 | tail -8
  timeout -s KILL 200 ./$b bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 5 2>&1 | grep -E "mesh alone|one copy|1024 copies|above"
 done
done
for s in c r b l; do ./tb compare --reference /tmp/${s}_tb.pfm /tmp/${s}_tn.pfm 2>&1 | tail -1; done
nvidia-smi --query-gpu=clocks.sm --format=csv,noheader
