for f in *.xz; do xz -dkf $f; chmod +x ${f%.xz}; done
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
cd ..; [ -e /work/main ] || { mkdir -p /work; ln -s $PWD /work/main; }
cd /work/main/tests && CI=1 timeout 400 /work/main/.dev/test_render --test-threads 4 2>&1 | grep -E "^test |test result|panicked|agree|seed" | head -60
