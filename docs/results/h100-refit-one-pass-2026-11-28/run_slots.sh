# The refit over primitive slots (each slot's leaf primitive written by its
# own invocation, the leaf's first slot climbing: treelet_slots) against the
# refit over collapsed nodes (treelet, ec4607b): alternated.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
./treelet bench dynamic --scene /tmp/bunny4.ply --frames 7 >/dev/null 2>&1
for i in 1 2; do
  for t in treelet treelet_slots; do
    echo "== $t"
    ./$t bench dynamic --scene /tmp/bunny4.ply --frames 7 2>&1 | grep -E "refit  |closest hits"
    ./$t bench dynamic --scene terrain:1000000 --frames 7 2>&1 | grep -E "refit  "
  done
done
for t in layouts tracer instances; do echo "== test $t"; timeout -s KILL 200 ./t_$t --test-threads 4 2>&1 | grep -E "test result|FAILED|panicked|failed"; done
