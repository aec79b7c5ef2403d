#!/bin/bash
# Instances opened into their meshes' subtrees (re-braiding) on the H200:
# the 940k bunny, 1024 copies, per opening depth; the old binary beside.
for f in treelet_new.xz treelet_old.xz t_instances.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply 2>&1 | tail -1
B="bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000,10000,100000 --repeats 7"
run() { echo "=== $*"; env "$@" 2>&1 | grep -E "top level|mesh alone|in place|copies|above|largest" ; }
run X=old timeout 200 ./treelet_old $B
for bits in 0 3 6; do run TREELET_INSTANCE_OPENING=$bits timeout 200 ./treelet_new $B --json $OUT/bunny4_open$bits.json; done
run X=default timeout 200 ./treelet_new $B --json $OUT/bunny4_default.json
cd ..
echo "== tests"
CI=true timeout 200 .dev/t_instances --test-threads 4 2>&1 | grep -E "^test |test result|panicked|assert"
