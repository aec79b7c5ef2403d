# Device: which cast parts crash NVIDIA's compiler; then spirv-reduce.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/ps.xz > /tmp/ps; chmod +x /tmp/ps
xz -dc .dev/carry/spirv-reduce.xz > /tmp/spirv-reduce; chmod +x /tmp/spirv-reduce
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee $OUT/gpu.txt
one() { local t0=$(date +%s%N); timeout 60 /tmp/ps "$1" > /tmp/one.log 2>&1; local rc=$?; echo "$rc $(( ($(date +%s%N) - t0) / 1000000 ))ms $1 $(tail -1 /tmp/one.log | cut -c1-160)"; }
{
for e in render::x_primary_cs render::x_diffuse_cs render::x_bounce_cs render::x_rays_cs render::x_occluded_cs render::x_diffuse_occluded_cs render::x_diffuse_lanes_cs render::x_any_nolanes_cs render::cast_classic_triangles_cs render::cast_instances_cs; do one $e; done
for f in .dev/x/*.spv; do one $f; done
} 2>&1 | tee $OUT/parts.txt
# Reduce the smallest crashing module: keep every interesting candidate.
best=$(grep "^139 " $OUT/parts.txt | grep "\.spv" | awk '{print $3}' | xargs -r ls -S | tail -1)
echo "reducing $best"; [ -n "$best" ] || exit 0
cat > /tmp/test.sh <<'T'
#!/bin/bash
timeout 60 /tmp/ps "$1" > /dev/null 2>&1
rc=$?
if [ $rc -eq 139 ]; then cp "$1" $OUT/best.spv; echo "$(date +%T) $(stat -c %s "$1")" >> $OUT/reduce.log; exit 0; fi
exit 1
T
chmod +x /tmp/test.sh; export OUT
cd /tmp && timeout ${RTIME:-300} /tmp/spirv-reduce --step-limit=${STEPS:-100000} "$OLDPWD/$best" -o $OUT/reduced.spv -- /tmp/test.sh > $OUT/reduce.out 2>&1; echo reduce rc $?
