for f in treelet.xz treelet_head.xz instances_test.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
python3 subdivide.py bunny.obj 4 bunny4.ply > /dev/null
./treelet bench instances --scene bunny4.ply --grid 2 --top-sizes 10 --repeats 1 --width 640 --height 480 > /dev/null 2>&1
for round in 1 2; do
  for v in head new; do
    bin=./treelet_$v; [ $v = new ] && bin=./treelet
    echo "== round $round: $v"
    $bin bench instances --scene bunny4.ply --grid 32 --top-sizes 1000 --repeats 7 2>&1 | grep -E "alone|in place|copies|above"
  done
done
echo "== instance tests on the GPU (debug test binary, CI=true)"
cd .. && CI=true ./.dev/instances_test 2>&1 | tail -8
