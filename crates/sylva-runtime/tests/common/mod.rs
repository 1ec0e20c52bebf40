//! Shared GPU for tests: one device per test process. In CI (`CI=true`) a missing adapter
//! fails the test; elsewhere the test is skipped with the reason printed.

use std::sync::Arc;
use sylva_gpu::GpuContext;

pub fn gpu() -> Option<Arc<GpuContext>> {
    match GpuContext::shared_arc() {
        Ok(ctx) => Some(ctx),
        Err(e) => {
            if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") {
                panic!("CI=true requires a GPU adapter (lavapipe will do): {e}");
            }
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}
