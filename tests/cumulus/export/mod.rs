//! `cumulus export`: the `.vol` and `.vdb` writers, authored scenes, the command's
//! defaults and refusals, any number of parcels, and the CPU density
//! against the GPU.

mod authored;
mod cli;
mod gpu;
mod many;
mod vdb;
mod vol;
