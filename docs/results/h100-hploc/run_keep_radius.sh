nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
./treelet bench rays --scene bunny4.ply --mesh-only --accels lbvh,trbvh --layouts bvh2 --width 1920 --height 1080 2>&1 | tail -2
for k in 0 8 4 2; do for r in 0 1 2 4 8; do
  export TREELET_HPLOC_KEEP=$k TREELET_HPLOC_RADIUS=$r
  sah=$(./treelet build --builder hploc --device gpu --scene bunny4.ply | grep -E "builder" | sed 's/.*SAH //')
  row=$(./treelet bench rays --scene bunny4.ply --mesh-only --accels hploc --layouts bvh2 --width 1920 --height 1080 2>&1 | tail -1)
  echo "keep $k radius $r sah $sah | $row"
done; done
