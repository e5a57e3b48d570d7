//! The GPU adapter of the GPU tests, and what a GPU test does on a machine
//! where it cannot run: it fails, naming the fix, unless the user opted
//! into skipping with `CUMULUS_SKIP_GPU_TESTS=1`; under `CI=true` it fails
//! even then (CI must never skip the GPU tests). A skipped test still
//! counts as passed in libtest's summary, so skipping is opt-in and says so
//! on stderr.

use std::io::Write;

use cumulus::render::GpuContext;

/// The variable that lets GPU tests skip where they cannot run.
pub const SKIP_VAR: &str = "CUMULUS_SKIP_GPU_TESTS";

/// What a GPU test does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Decision {
    /// What it needs is there.
    Run,
    /// Missing, and the user asked to skip (outside CI): return early.
    Skip,
    /// Missing, and no skip asked for (or CI): fail.
    Fail,
}

/// The policy: `ci` is `CI=true`, `skip` is `CUMULUS_SKIP_GPU_TESTS=1`,
/// `found` whether the adapter (or, for the window tests, the display) is
/// there.
pub fn gpu_policy(ci: bool, skip: bool, found: bool) -> Decision {
    match (found, skip && !ci) {
        (true, _) => Decision::Run,
        (false, true) => Decision::Skip,
        (false, false) => Decision::Fail,
    }
}

fn env_is(name: &str, value: &str) -> bool {
    std::env::var(name).as_deref() == Ok(value)
}

/// `found`, or what [`gpu_policy`] says to do for the test named by `what`
/// when it is an error: None when the user opted into skipping (after
/// printing `SKIPPED (missing): what`), else a panic naming what is
/// `missing`, the error and the `fix`.
pub fn require<T, E: std::fmt::Display>(
    what: &str,
    found: Result<T, E>,
    missing: &str,
    fix: &str,
) -> Option<T> {
    let ci = env_is("CI", "true");
    let decision = gpu_policy(ci, env_is(SKIP_VAR, "1"), found.is_ok());
    let why = match found {
        Ok(t) => return Some(t),
        Err(e) => e,
    };
    match decision {
        Decision::Skip => {
            // Straight to stderr, past libtest's capture: a skipped test
            // counts as passed, so the skip must show even then.
            let _ = writeln!(std::io::stderr(), "SKIPPED ({missing}): {what}");
            None
        }
        _ if ci => panic!(
            "{what}: {missing} ({why}). CI=true needs it ({SKIP_VAR} is ignored there): {fix}"
        ),
        _ => panic!(
            "{what}: {missing} ({why}). To run the GPU tests, {fix}; to skip them on this \
             machine instead, set {SKIP_VAR}=1"
        ),
    }
}

/// How to get a GPU adapter on a machine without a GPU.
pub const ADAPTER_FIX: &str = "install Mesa's CPU Vulkan driver (Debian/Ubuntu: `apt-get install \
     mesa-vulkan-drivers libvulkan1`)";

/// The CPU Vulkan adapter (lavapipe "llvmpipe"), or any adapter when that is
/// absent. With none: see [`require`] (a panic naming `what` and the fix,
/// or None when skipping was asked for outside CI).
pub fn context(what: &str) -> Option<GpuContext> {
    let ctx =
        GpuContext::new_headless(Some("llvmpipe")).or_else(|_| GpuContext::new_headless(None));
    require(what, ctx, "no GPU adapter", ADAPTER_FIX)
}

#[test]
fn gpu_policy_fails_without_an_adapter_unless_skipping_is_asked_outside_ci() {
    use Decision::*;
    // (CI, CUMULUS_SKIP_GPU_TESTS, adapter found) -> decision
    let table = [
        ((false, false, true), Run),
        ((false, true, true), Run),
        ((true, false, true), Run),
        ((true, true, true), Run),
        ((false, false, false), Fail),
        ((false, true, false), Skip),
        ((true, false, false), Fail),
        ((true, true, false), Fail),
    ];
    for ((ci, skip, found), want) in table {
        assert_eq!(
            gpu_policy(ci, skip, found),
            want,
            "CI {ci}, skip {skip}, found {found}"
        );
    }
}
