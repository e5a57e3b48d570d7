//! The sky: the atmosphere model, aerial perspective and the sun's position.

mod aerial;
mod model;
mod sun;
