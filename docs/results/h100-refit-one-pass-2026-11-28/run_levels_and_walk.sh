# Diagnostic build (treelet_diag, not committed): the refit's climb cut after
# N levels (TREELET_DIAG_LEVELS, 0 = all; LayoutParams::_pad0 passed to
# refit_kernel), relaxed counters (TREELET_DIAG_RELAXED); and the instanced
# walk with `leaf` returning whether it found a closer hit (instead of a
# copy of the hit compared every step).
for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
./pipeline_stats render::cast_instances_cs render::cast_bvh2_triangles_cs 2>&1 | tail -2; ./pipeline_stats_diag render::cast_instances_cs 2>&1 | tail -1
python3 subdivide.py bunny.obj 4 /tmp/bunny4.ply > /dev/null
./treelet bench dynamic --scene /tmp/bunny4.ply --frames 7 >/dev/null 2>&1
for L in 1 2 4 8 12 16 20 24 28 32 40 48 0; do
  echo "levels $L: $(TREELET_DIAG_LEVELS=$L ./treelet_diag bench dynamic --scene /tmp/bunny4.ply --frames 7 2>&1 | grep -E 'refit  ')"
done
echo "relaxed: $(TREELET_DIAG_RELAXED=1 ./treelet_diag bench dynamic --scene /tmp/bunny4.ply --frames 7 2>&1 | grep -E 'refit  ')"
echo "terrain levels 1: $(TREELET_DIAG_LEVELS=1 ./treelet_diag bench dynamic --scene terrain:1000000 --frames 7 2>&1 | grep -E 'refit  ')"
echo "terrain all: $(./treelet_diag bench dynamic --scene terrain:1000000 --frames 7 2>&1 | grep -E 'refit  ')"
./treelet bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 5 >/dev/null 2>&1
for i in 1 2; do
  for t in treelet treelet_diag; do
    echo "== $t"
    ./$t bench instances --scene /tmp/bunny4.ply --grid 32 --top-sizes 1000 --repeats 5 2>&1 | grep -E "mesh alone|one copy|1024 copies|above"
  done
done
