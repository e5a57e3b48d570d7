//! `cumulus export`: the `.vol` writer, authored scenes, and the CPU density
//! against the GPU.

mod authored;
mod gpu;
mod vol;
