# --integrator auto on the H100: what the pilot measures and picks, and
# what it costs, beside nee and caustics named.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--width 1024 --height 768 --spp 1024"
./treelet render $R --spp 4 --integrator caustics --out /tmp/w.png 2>&1 | tail -1
./treelet render $R --spp 4 --integrator caustics --scene ../scenes/room_disk.json --out /tmp/w.png 2>&1 | tail -1
for sc in cornell ../scenes/room_disk.json; do
  for i in 1 2 3; do
    ./treelet render $R --scene $sc --seed $i --integrator auto --explain --out /tmp/a.png 2>&1 | grep -E "^integrator|M camera paths" | sed -e 's/.*M camera paths\/s; /  /'
  done
  for it in nee caustics; do for i in 1 2; do
    echo "$it: $(./treelet render $R --scene $sc --seed $i --integrator $it --out /tmp/a.png 2>&1 | tail -1 | sed -e 's/.*M camera paths\/s; //')"
  done; done
done
