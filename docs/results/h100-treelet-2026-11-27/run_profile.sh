for f in treelet.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
echo "== trbvh 1M"; ./treelet bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -12
echo "== trbvh 1M per level"; TREELET_PROFILE_LEVELS=1 ./treelet bench build --builder trbvh --sizes 1000000 --repeats 7 2>&1 | tail -150
echo "== empty"; TREELET_PROFILE_LEVELS=empty ./treelet bench build --builder trbvh --sizes 1000000 --repeats 5 2>&1 | grep -E "empty" | head -120
