//! Helpers shared by the integration tests that need a GPU adapter.

#![allow(dead_code)] // each test binary uses its own subset

use cumulus::render::GpuContext;

/// The CPU Vulkan adapter (lavapipe "llvmpipe"), or any adapter when that is
/// absent. With none: a notice naming `what` and `None`, or a panic when
/// CI=true (CI must not silently skip the GPU tests).
pub fn context(what: &str) -> Option<GpuContext> {
    let ctx =
        GpuContext::new_headless(Some("llvmpipe")).or_else(|_| GpuContext::new_headless(None));
    match ctx {
        Ok(c) => Some(c),
        Err(e) => {
            if std::env::var("CI").as_deref() == Ok("true") {
                panic!("CI=true needs a GPU adapter (lavapipe): {e}");
            }
            eprintln!("NOTICE: skipping {what}, no adapter: {e}");
            None
        }
    }
}
