//! Helpers shared by the integration tests.
use std::sync::{Arc, OnceLock};

use treelet::gpu::GpuContext;

/// The GPU context for tests. With `CI` set, a missing adapter fails the
/// test; elsewhere the test is skipped with a printed reason (never silently).
pub fn gpu() -> Option<Arc<GpuContext>> {
    static CTX: OnceLock<Result<Arc<GpuContext>, String>> = OnceLock::new();
    match CTX.get_or_init(|| GpuContext::new().map_err(|e| format!("{e:#}"))) {
        Ok(ctx) => Some(ctx.clone()),
        Err(e) if std::env::var_os("CI").is_some() => panic!("CI is set and no GPU adapter is usable: {e}"),
        Err(e) => {
            eprintln!("SKIPPED (no GPU adapter, CI not set): {e}");
            None
        }
    }
}
