for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
for l in 4 6; do python3 subdivide.py bunny.obj $l bunny$l.ply > /dev/null; done
./treelet build --builder trbvh --scene bunny4.ply > /dev/null 2>&1
for l in 4 6; do echo "== trbvh bunny$l"; ./treelet build --builder trbvh --scene bunny$l.ply 2>&1 | grep -E "time|SAH"; done
echo "== trbvh random"; ./treelet bench build --builder trbvh --sizes 1000000,4000000,16000000 --repeats 5 2>&1 | tail -4
for l in 4 6; do echo "== levels bunny$l"; TREELET_PROFILE_LEVELS=1 ./treelet build --builder trbvh --scene bunny$l.ply 2>&1 | grep time | tr ',' '\n' ; done
