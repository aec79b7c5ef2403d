#!/usr/bin/env bash
# Reinsertion searched from the largest nodes only (TREELET_REINSERT_SHARE), over the TRBVH's rounds
# and over H-PLOC's tree, on the real-scene suite, against the defaults (run first and last) and
# OptiX (Mitsuba 3's peer) in the same call.
# Carry: .gl (NVIDIA's Vulkan loader, see ../../../../shared/docs/rust-gpu.md), .whl (slim-wheels.sh),
# .dev/carry/treelet.xz (the release binary, stripped, xz).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/treelet.xz > /tmp/T; chmod +x /tmp/T
(cd /tmp && tar xJf $OLDPWD/.whl/site.tar.xz)  # slim-wheels.sh, then every plugin but the peers' removed
mkdir -p /tmp/j
c="--suite --width 1920 --height 1080 --repeats 5 --layouts bvh2,cwbvh"
T0=$(date +%s); LIMIT=${LIMIT:-540}
run() { name=$1; acc=$2; shift 2; s=$(date +%s); if [ $((s - T0)) -gt $LIMIT ]; then echo "$name skipped (time)"; return; fi; env "$@" timeout 100 /tmp/T bench rays $c --accels $acc ${X:-} --json /tmp/j/$name.json > /tmp/j/$name.log 2>&1; echo "$name rc=$? $(( $(date +%s) - s ))s"; tail -1 /tmp/j/$name.log; }
for cfg in ${CONFIGS:-O D1 S05R2 S05R4 T1S05R4 HS05R4 HS05R8 HS02R8 HS10R4 HS05R8C0 T1S10R8 D2}; do
  case $cfg in
    O) X=--with-optix run O trbvh,hploc PYTHONPATH=/tmp/site ;;
    D1|D2) run $cfg trbvh X=1 ;;
    S05R2) run $cfg trbvh TREELET_REINSERT_SHARE=0.05 ;;
    S05R4) run $cfg trbvh TREELET_REINSERT_SHARE=0.05 TREELET_REINSERT=4 ;;
    T1S05R4) run $cfg trbvh TREELET_TREELETS=1,3,8 TREELET_REINSERT_SHARE=0.05 TREELET_REINSERT=4 ;;
    T1S10R8) run $cfg trbvh TREELET_TREELETS=1,3,8 TREELET_REINSERT_SHARE=0.1 TREELET_REINSERT=8 ;;
    HS05R4) run $cfg hploc TREELET_REINSERT_SHARE=0.05 TREELET_REINSERT=4 ;;
    HS05R8) run $cfg hploc TREELET_REINSERT_SHARE=0.05 TREELET_REINSERT=8 ;;
    HS02R8) run $cfg hploc TREELET_REINSERT_SHARE=0.02 TREELET_REINSERT=8 ;;
    HS10R4) run $cfg hploc TREELET_REINSERT_SHARE=0.1 TREELET_REINSERT=4 ;;
    HS05R8C0) run $cfg hploc TREELET_REINSERT_SHARE=0.05 TREELET_REINSERT=8 TREELET_REINSERT_CLIMB=0 ;;
    HR2) run $cfg hploc TREELET_REINSERT=2 ;;
  esac
done
tar czf $OUT/runs${TAG:-}.tgz -C /tmp/j .
nvidia-smi --query-gpu=clocks.sm --format=csv
