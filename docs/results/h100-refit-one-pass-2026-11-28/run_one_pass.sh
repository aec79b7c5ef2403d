# The bvh2 refit in one dispatch (boxes written into the layout's nodes by
# the climb) against the build before it; old and new alternated.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
./pipeline_stats bvh2::refit_cs bvh2::refit_state_cs 2>&1 | tail -3
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
./treelet bench dynamic --scene /tmp/bunny4.ply --frames 7 >/dev/null 2>&1
for i in 1 2 3; do
  for t in treelet_old treelet; do
    echo "== $t"
    ./$t bench dynamic --scene /tmp/bunny4.ply --frames 7 2>&1 | grep -E "refit  |rays"
    ./$t bench dynamic --scene terrain:1000000 --frames 7 2>&1 | grep -E "refit  "
  done
done
echo "== one full output"; ./treelet bench dynamic --scene /tmp/bunny4.ply --frames 7 2>&1 | tail -25
for t in layouts tracer instances; do echo "== test $t"; timeout -s KILL 200 ./$t --test-threads 4 2>&1 | grep -E "test result|FAILED|panicked|failed"; done
