//! The GPU core every render method builds on: the device
//! ([`GpuContext`]), the target formats and shared bind-group layouts
//! ([`layouts`]), the pipeline cache and its background builder
//! ([`pipelines`]), the WGSL modules ([`shaders`]), the frame's input and
//! uniform ([`frame`], [`uniform`]), the noise texture ([`noise`]), the
//! pass timing ([`timing`]) and what each pass needs from the adapter
//! ([`requires`]).

mod context;
pub mod frame;
pub mod layouts;
pub mod method;
pub mod noise;
pub mod pass;
pub mod passes;
pub mod pipelines;
pub(crate) mod prebuild;
pub mod requires;
pub mod resources;
pub mod shaders;
pub mod timing;
pub mod uniform;

pub use context::{GpuContext, begin_pass, catching, stored_color};
pub use frame::FrameInput;
