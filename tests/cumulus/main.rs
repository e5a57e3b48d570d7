//! The integration tests of cumulus, as one test binary (as wgpu's own
//! suite is): one link of the crate for all of them, and one place for
//! their shared helpers (`common`). Each area is a module, each topic a
//! module of its area; filter with the module path, e.g.
//! `cargo test --release --test cumulus -- physics::`.
//!
//! The tests share one process: none may change process-wide state (the
//! current directory, environment variables, the global rayon pool) or
//! assume it runs alone, and temporary files go in a `tempfile` directory
//! of their own.

mod common;

mod atmosphere;
mod authored;
mod bad_input;
mod bench;
mod docs;
mod export;
mod layering;
mod physics;
mod render;
mod scene;
mod sky;
mod sprites;
mod window;
