for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
xz -dc .dev/carry/ps.xz > /tmp/ps; chmod +x /tmp/ps
while read e; do timeout 60 /tmp/ps $e > /tmp/one.log 2>&1; rc=$?; echo "$rc $e $(tail -1 /tmp/one.log | cut -c1-150)"; done < .dev/entries.txt > $OUT/ps.txt
grep -v "^0 " $OUT/ps.txt; grep -c "^0 " $OUT/ps.txt
