//! Wang 2003's sprite clouds: the CPU model, the per-vertex mechanisms, the
//! impostor ring, and the `sprites` method on the GPU.

mod clouds;
mod compositing;
mod gpu;
mod ring;
mod wang;
