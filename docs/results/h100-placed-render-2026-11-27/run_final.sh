# The session's final build on the H100: the GPU tests of instances and
# layouts, a placed render and cornell.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
python3 subdivide.py bunny.obj 2 /tmp/bunny2.ply > /dev/null
python3 gen_room.py /tmp/bunny2.ply 1024 /tmp/room_b2_1024.json
./treelet render --scene /tmp/room_b2_1024.json --width 1024 --height 768 --spp 64 --device gpu --out /tmp/p.png 2>&1 | tail -1
./treelet render --scene cornell --width 1024 --height 768 --spp 1024 --device gpu --out /tmp/c.png 2>&1 | tail -1
for t in instances layouts; do echo "== test $t"; ./$t --test-threads 4 2>&1 | grep -E "test result|FAILED|panicked|failed"; echo "exit ${PIPESTATUS[0]}"; done
