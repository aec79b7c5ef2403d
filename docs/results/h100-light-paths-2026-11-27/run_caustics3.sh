for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu"
./treelet render $R --spp 4 --out /tmp/w.png 2>&1 | tail -1
S=../scenes/room_disk.json
for seed in 99 98; do for I in nee caustics; do timeout -s KILL 120 ./treelet render --scene $S $R --integrator $I --spp 4096 --seed $seed --out /tmp/ref_${I}_$seed.exr 2>&1 | tail -1; done; done
echo "== the references against each other (noise of 4096 spp; the same limit?)"
for a in nee caustics; do for b in nee caustics; do echo "  $a 99 vs $b 98: $(./treelet compare --reference /tmp/ref_${b}_98.exr /tmp/ref_${a}_99.exr | tail -1)"; done; done
for I in nee caustics; do for spp in 256 1024; do timeout -s KILL 120 ./treelet render --scene $S $R --integrator $I --spp $spp --seed 7 --out /tmp/room_${I}_$spp.exr 2>&1 | tail -1; for r in nee_99 caustics_99; do echo "  $I $spp vs $r: $(./treelet compare --reference /tmp/ref_$r.exr /tmp/room_${I}_$spp.exr 2>&1 | tail -1)"; done; done; done
cp /tmp/room_caustics_1024.exr /tmp/room_nee_1024.exr /tmp/ref_caustics_99.exr $OUT/ 2>/dev/null
