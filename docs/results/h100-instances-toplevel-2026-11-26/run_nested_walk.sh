for f in treelet.xz treelet_flat.xz instances_test.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
python3 subdivide.py bunny.obj 2 bunny2.ply > /dev/null
./treelet bench instances --scene bunny2.ply --grid 2 --top-sizes 10 --repeats 1 --width 640 --height 480 2>&1 | tail -3
for round in 1 2; do
  for v in flat new; do
    bin=./treelet_$v; [ $v = new ] && bin=./treelet
    echo "== round $round: $v"
    $bin bench instances --scene bunny4.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7 --json $OUT/instances_bunny4_${v}_r$round.json 2>&1
  done
done
echo "== new, bunny2"
./treelet bench instances --scene bunny2.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7 --json $OUT/instances_bunny2_new.json 2>&1
echo "== instance tests on the GPU (debug test binary, CI=true)"
cd .. && CI=true ./.dev/instances_test 2>&1 | tail -8
