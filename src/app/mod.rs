//! The live window (winit + egui): watch clouds form, edit the profile.
//!
//! - [`profile_edit`]: the profile editor's state and every edit the panel
//!   makes (plain functions, also called by the tests);
//! - [`camera`]: orbit/fly camera maths;
//! - [`state`]: the model the panel edits (scene, editor, simulation,
//!   playback, settings), free of window and GPU types;
//! - [`panel`]: the egui side panel;
//! - [`clamps_panel`]: the panel's clamp report (by kind, since the last reset);
//! - [`slices_panel`]: the slices method's qualitative controls and the
//!   authored ellipsoids' editor;
//! - [`ellipsoid_mouse`]: picking, moving and resizing the ellipsoids with
//!   the mouse, and their outlines;
//! - [`skewt_panel`]: the profile diagram's height–T and Skew-T views, the
//!   panel's hodograph;
//! - [`progress`]: the pre-simulation to the start time on a terminal bar;
//! - [`window`]: winit event loop, surface, frame loop and screenshot;
//! - `draw`: what one window frame records (3D view, panel, read-back).

pub mod camera;
pub mod clamps_panel;
mod draw;
pub mod ellipsoid_mouse;
pub mod panel;
pub mod profile_edit;
pub mod progress;
pub mod skewt_panel;
pub mod slices_panel;
pub mod state;
pub mod window;

pub use window::{WatchOptions, run};
