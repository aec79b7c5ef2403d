for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
cd ..
R="--scene scenes/room_disk.json --width 1024 --height 768 --device gpu"
./.dev/pipeline_stats render::mixed::bvh2_cs render::full::bvh2_cs render::spheres::linear_cs 2>&1 | tail -8
echo "== reference: nee 2048 spp seed 99"; ./.dev/treelet render $R --spp 2048 --seed 99 --integrator nee --out /tmp/ref.exr 2>&1 | tail -1
./.dev/treelet render $R --spp 16 --integrator caustics --out /tmp/w.exr > /dev/null 2>&1
for round in 1 2; do
for spp in 256 1024; do
  for b in treelet_old:nee treelet:nee treelet:caustics; do t=${b%%:*}; i=${b##*:}
    echo "== $t $i $spp spp (round $round)"; ./.dev/$t render $R --spp $spp --seed $round --integrator $i --out /tmp/$t-$i-$spp.exr 2>&1 | tail -1
    ./.dev/treelet compare --reference /tmp/ref.exr /tmp/$t-$i-$spp.exr
  done
done
done
echo "== reference noise: a second nee 2048 spp (seed 98) against the first"; ./.dev/treelet render $R --spp 2048 --seed 98 --integrator nee --out /tmp/ref2.exr 2>&1 | tail -1; ./.dev/treelet compare --reference /tmp/ref.exr /tmp/ref2.exr
echo "== cornell 1024 spp"; for b in treelet_old:nee treelet:nee treelet:caustics; do t=${b%%:*}; i=${b##*:}; ./.dev/$t render --scene cornell --width 1024 --height 768 --device gpu --spp 1024 --integrator $i --out /tmp/c.png 2>&1 | tail -1; done
echo "== room with a square light of the disk's area (experiment: 2 triangles instead of 64)"; ./.dev/treelet render --scene .dev/quad/room_disk.json --width 1024 --height 768 --device gpu --spp 256 --integrator nee --explain --out /tmp/q.png 2>&1 | grep -E "accel|scenes|room_disk.json:"
