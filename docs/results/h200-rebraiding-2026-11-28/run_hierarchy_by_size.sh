#!/bin/bash
# Top-level builds with the plain and the subgroup agglomerative hierarchy, by size (H200).
xz -dkf treelet_main.xz; chmod +x treelet_main
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
for rep in 1 2; do
for h in agglomerative subgroup; do
  echo "=== $h ($rep)"
  TREELET_HIERARCHY=$h ./treelet_main bench instances --scene terrain:20000 --grid 4 --width 256 --height 256 --top-sizes 50000,100000,150000,200000,400000 --repeats 15 2>&1 | grep -E "top level"
done
done
