for f in .gl/*.deb; do dpkg -x $f / ; done >/dev/null 2>&1; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json CI=true
exec > >(tee $OUT/log.txt) 2>&1
cd .dev
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
R="--scene ../scenes/room_disk.json --width 1024 --height 768"
timeout -s KILL 60 ./treelet render $R --spp 4 --out /tmp/w.exr 2>&1 | tail -1
timeout -s KILL 120 ./treelet render $R --spp 4096 --seed 99 --out /tmp/room_4096.exr 2>&1 | tail -1
for spp in 16 64 256 1024; do timeout -s KILL 120 ./treelet render $R --spp $spp --seed 7 --out /tmp/room_$spp.exr 2>&1 | tail -1; done
for spp in 16 64 256 1024; do echo "spp $spp: $(./treelet compare --reference /tmp/room_4096.exr /tmp/room_$spp.exr 2>&1 | tail -1)"; done
