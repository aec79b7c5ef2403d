#!/usr/bin/env bash
# The engine API's tests on the H200 (CI=true: a GPU test without an adapter fails).
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export CI=true
for t in tracer_test instances_test; do xz -dc .dev/carry/$t.xz > /tmp/$t; chmod +x /tmp/$t; done
/tmp/tracer_test 2>&1 | grep -E "^test |test result|panicked|seed" | head -30
/tmp/instances_test 2>&1 | grep -E "^test |test result|panicked" | head -20
xz -dc .dev/carry/engine_frames.xz > /tmp/ef; chmod +x /tmp/ef; /tmp/ef 3 /tmp/x.png | head -1
