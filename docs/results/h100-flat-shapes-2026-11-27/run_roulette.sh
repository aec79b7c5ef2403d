for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --device gpu"
for sc in cornell ../scenes/room_disk.json; do
  n=$(basename $sc .json)
  ./treelet_d3 render --scene $sc $R --spp 4096 --seed 99 --out /tmp/ref_$n.exr 2>&1 | tail -1
  for T in 3 4 5; do ./treelet_d$T render --scene $sc $R --spp 16 --out /tmp/w.png > /dev/null 2>&1; done
  for k in 1 2; do for T in 3 4 5; do for spp in 256 1024; do
    line=$(./treelet_d$T render --scene $sc $R --spp $spp --seed 7 --out /tmp/x_$n.exr 2>&1 | tail -1 | grep -oE "[0-9.]+ s \(|kernels [0-9.]+ s")
    echo "$n roulette-depth $T spp $spp: $(echo $line | tr '\n' ' ') $(./treelet_d3 compare --reference /tmp/ref_$n.exr /tmp/x_$n.exr 2>&1 | tail -1 | grep -oE '"rmse":[0-9.]+')"
  done; done; done
done
