#!/bin/bash
# usage: exp.sh scene name ; prints rmse per sampler/spp/seed
B=${B:-/tmp/qmc/treelet_new}
scene=$1; n=$2
for spp in 16 64 256; do for smp in independent sobol; do for seed in 1 2; do
  $B render --scene $scene --width 128 --height 96 --spp $spp --seed $seed --sampler $smp --device cpu --out /tmp/qmc/o_$n.exr >/dev/null 2>&1
  r=$($B compare --reference /tmp/qmc/ref_$n.exr /tmp/qmc/o_$n.exr)
  echo "$n spp $spp $smp seed $seed $r"
done; done; done
