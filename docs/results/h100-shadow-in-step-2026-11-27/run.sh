# The scan's shadow ray traced in the step of its bounce (new) against in
# the path's next step (old): cornell and the disk-lit room (both scans),
# 1024x768x1024, interleaved, render-kernel time; images compared.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
./pipeline_stats render::spheres::linear_cs render::full::linear_cs 2>&1 | grep Register
R="--width 1024 --height 768 --spp 1024"
./treelet_new render $R --spp 16 --out /tmp/w.png 2>&1 | tail -1
./treelet_old render $R --spp 16 --out /tmp/w.png 2>&1 | tail -1
for sc in cornell ../scenes/room_disk.json; do
  for i in 1 2 3 4 5; do
    for b in old new; do
      echo "$b $sc: $(./treelet_$b render $R --scene $sc --out /tmp/$b.exr 2>&1 | tail -1 | grep -o 'kernel [a-z_]*\|kernels [0-9.]* s\|process [0-9.]* s' | tr '\n' ' ')"
    done
  done
  ./treelet_new compare --reference /tmp/old.exr /tmp/new.exr
  for b in old new; do
    echo "$b $sc smallpt: $(./treelet_$b render $R --scene $sc --integrator smallpt --out /tmp/$b.exr 2>&1 | tail -1 | grep -o 'kernels [0-9.]* s')"
  done
done
