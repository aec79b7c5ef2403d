#!/usr/bin/env bash
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export CI=true
xz -dc .dev/carry/treelet_a.xz > /tmp/A; xz -dc .dev/carry/treelet_d.xz > /tmp/D; chmod +x /tmp/A /tmp/D
for b in A D; do for dev in gpu cpu; do for s in terrain:20000 random:20000:7; do for acc in lbvh trbvh hploc; do
  /tmp/$b build --scene $s --builder $acc --device $dev --json 2>/dev/null | python3 -c "import json,sys; d=json.load(sys.stdin); print('$b $dev $s $acc', d['sah_cost'], d['epo'], d['nodes'])"
done; done; done; done
xz -dc .dev/carry/t_layouts.xz > /tmp/layouts; chmod +x /tmp/layouts
TREELET_TEST_SEED=12345 /tmp/layouts gpu_layouts_equal_cpu bvh2_refit_in_place 2>&1 | grep -v "^$" | head -30
