# The instanced walk with its world ray and instance in the stack's last words
# (and the refit's counters kept between refits): old and new alternated.
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
./pipeline_stats render::cast_instances_cs render::cast_bvh2_triangles_cs render::render_placed_cs bvh2::refit_cs 2>&1 | tail -4
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
./treelet bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 5 >/dev/null 2>&1
for i in 1 2; do
  for t in treelet_old treelet; do
    echo "== $t"
    ./$t bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 5 2>&1 | grep -E "mesh alone|one copy|1024 copies|above"
    ./$t bench dynamic --scene /tmp/bunny4.ply --frames 7 2>&1 | grep -E "refit  "
    ./$t bench dynamic --scene terrain:1000000 --frames 7 2>&1 | grep -E "refit  "
  done
done
