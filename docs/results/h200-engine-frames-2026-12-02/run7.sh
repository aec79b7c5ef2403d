#!/usr/bin/env bash
# The engine example on the H200: an engine's own device, its mesh in its buffers, refit, trace, shade.
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm --format=csv
xz -dc .dev/carry/engine_frames.xz > /tmp/ef; chmod +x /tmp/ef
for k in 1 2; do /tmp/ef 120 $OUT/engine_frames_$k.png; done
nvidia-smi --query-gpu=clocks.sm --format=csv
