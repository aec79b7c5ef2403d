# The climb's arrival split into a release add and, for the second arrival
# only, an acquire fence (treelet_fence), against the refit in one dispatch
# with acquire-release adds (treelet, ec4607b) and the build before
# (treelet_old, a7507ed): alternated.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
./treelet bench dynamic --scene /tmp/bunny4.ply --frames 7 >/dev/null 2>&1
for i in 1 2 3; do
  for t in treelet_old treelet treelet_fence; do
    echo "== $t"
    ./$t bench dynamic --scene /tmp/bunny4.ply --frames 7 2>&1 | grep -E "refit  |rebuild"
    ./$t bench dynamic --scene terrain:1000000 --frames 7 2>&1 | grep -E "refit  |rebuild"
  done
done
echo "== one full output"; ./treelet_fence bench dynamic --scene /tmp/bunny4.ply --frames 7 2>&1 | tail -8
for t in layouts tracer instances gpu_vs_cpu treelet; do echo "== test $t"; timeout -s KILL 200 ./t_$t --test-threads 4 2>&1 | grep -E "test result|FAILED|panicked|failed"; done
