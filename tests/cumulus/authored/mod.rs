//! Schpok 2003's authored clouds on the CPU: the model, mouse editing and
//! the slicing geometry (the GPU side is `methods::slices::gpu`).

mod clouds;
mod model;
mod pick;
mod slicing;
