for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name --format=csv,noheader
timeout -s KILL 60 ./treelet render --scene terrain:1000000 --accel lbvh --width 256 --height 192 --spp 1 --out /tmp/w.png 2>&1 | tail -1
for rep in 1 2; do for a in lbvh trbvh hploc; do for s in 4 36; do echo "== $a spp $s"; timeout -s KILL 60 ./treelet render --scene terrain:1000000 --accel $a --width 1024 --height 768 --spp $s --out /tmp/t.png 2>&1 | tail -1; done; done; done
echo "== rays"; timeout -s KILL 90 ./treelet bench rays --scene terrain:1000000 --mesh-only --accels lbvh,trbvh,hploc --layouts bvh2 --width 1920 --height 1080 --repeats 7 2>&1 | tail -4
echo "== builds"; for b in lbvh hploc; do timeout -s KILL 90 ./treelet bench build --builder $b --sizes 4096,16384,65536,262144,1000000,4000000 --repeats 11 2>&1 | tail -7; done
