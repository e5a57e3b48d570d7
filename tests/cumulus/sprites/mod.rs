//! Wang 2003's sprite clouds: the CPU model, the per-vertex mechanisms, the
//! impostor ring, the `sprites` method on the GPU, and its look.

mod clouds;
mod compositing;
mod gpu;
mod look;
mod ring;
mod wang;
