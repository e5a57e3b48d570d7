//! The live window: under Xvfb on the CPU adapter, and its panels and
//! profile editing headless.

mod live;
mod panel;
mod profile_edit;
mod slices_panel;
