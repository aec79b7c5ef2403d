#!/bin/bash
# Top-level builds over 1k/10k/100k instances on the H200: stages, with knobs.
xz -dkf treelet.xz; chmod +x treelet
nvidia-smi --query-gpu=name,driver_version,clocks.sm --format=csv
run() { echo "=== $*"; env "$@" ./treelet bench instances --scene terrain:20000 --grid 4 --width 256 --height 256 --top-sizes 1000,10000,100000 --repeats 15 --json $OUT/tlas_$(echo "$*" | tr ' =' '__').json 2>&1 | grep -v "^\s*$" | tail -25; }
run X=default
run TREELET_HIERARCHY=agglomerative
run TREELET_HIERARCHY=radix
run TREELET_SORT_HIGH_FIRST=0
run TREELET_MORTON_KEY_BITS=30
run TREELET_SORT_TILES=small
run TREELET_SORT_TILES=multisplit
run X=default2
