xz -dkf .dev/test_render.xz; chmod +x .dev/test_render
(cd tests && CI=true timeout -s KILL 150 ../.dev/test_render --test-threads 8 2>&1 | grep -E "^test |test result|FAILED|panicked|failed" | head -30)
