# Session of 2026-11-27 (eighth), H100: the bvh2 refit in one dispatch,
# the top level unchanged, cornell's kernel after the integrator's one
# lookup for copies, and renders of copies kept placed against flattened.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv,noheader
python3 subdivide.py bunny.obj 2 /tmp/bunny2.ply > /dev/null
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
for r in 1 2; do for bin in treelet_prev treelet; do for sc in terrain:1000000 /tmp/bunny4.ply; do
  echo "== $bin bench dynamic $sc (round $r)"
  ./$bin bench dynamic --scene $sc --frames 7 --width 1920 --height 1080 2>&1 | grep -E "refit|closest|occlusion|rror"
done; done; done
python3 gen_room.py /tmp/bunny2.ply 256 /tmp/room_b2_256.json
python3 gen_room.py /tmp/bunny2.ply 1024 /tmp/room_b2_1024.json
python3 gen_room.py /tmp/bunny4.ply 1024 /tmp/room_b4_1024.json
for sc in room_b2_256 room_b2_1024 room_b4_1024; do for mode in placed flatten; do
  flag=""; [ $mode = flatten ] && flag="--flatten"
  echo "== render $sc $mode"
  /usr/bin/time -f "process %e s, max RSS %M KB" ./treelet render --scene /tmp/$sc.json $flag --width 1024 --height 768 --spp 64 --device gpu --explain --out $OUT/${sc}_$mode.png 2>&1 | grep -E "wrote|process|error|timeline"
done; done
for t in instances layouts; do echo "== test $t"; ./$t --test-threads 4 2>&1 | grep -E "test result|FAILED|panicked|failed"; echo "exit ${PIPESTATUS[0]}"; done
