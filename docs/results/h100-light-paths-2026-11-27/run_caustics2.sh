for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu"
for T in ./treelet_before ./treelet; do timeout -s KILL 60 $T render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1; done
echo "== cornell nee 1024 spp, before (c428c28) / now, interleaved"
for i in 1 2 3; do for T in ./treelet_before ./treelet; do echo -n "$T: "; timeout -s KILL 60 $T render $R --spp 1024 --out /tmp/c.png 2>&1 | tail -1; done; done
echo "== room nee before/now"
for i in 1 2; do for T in ./treelet_before ./treelet; do echo -n "$T: "; timeout -s KILL 60 $T render --scene ../scenes/room_disk.json $R --spp 1024 --out /tmp/r.png 2>&1 | tail -1; done; done
echo "== reference: room nee 4096 spp seed 99"
timeout -s KILL 120 ./treelet render --scene ../scenes/room_disk.json $R --spp 4096 --seed 99 --out /tmp/room_ref.exr 2>&1 | tail -1
for I in nee caustics; do for spp in 64 256 1024; do timeout -s KILL 120 ./treelet render --scene ../scenes/room_disk.json $R --integrator $I --spp $spp --seed 7 --out /tmp/room_${I}_$spp.exr 2>&1 | tail -1; echo "  $I $spp: $(./treelet compare --reference /tmp/room_ref.exr /tmp/room_${I}_$spp.exr 2>&1 | tail -1)"; done; done
echo "== reference: room caustics 4096 spp seed 99 (against which both again)"
timeout -s KILL 120 ./treelet render --scene ../scenes/room_disk.json $R --integrator caustics --spp 4096 --seed 99 --out /tmp/room_refc.exr 2>&1 | tail -1
for I in nee caustics; do for spp in 64 256 1024; do echo "  $I $spp vs caustics ref: $(./treelet compare --reference /tmp/room_refc.exr /tmp/room_${I}_$spp.exr 2>&1 | tail -1)"; done; done
cp /tmp/room_caustics_1024.exr /tmp/room_nee_1024.exr $OUT/ 2>/dev/null
echo "== cornell caustics 1024"
timeout -s KILL 60 ./treelet render $R --integrator caustics --spp 1024 --out $OUT/cornell_caustics.png 2>&1 | tail -1
