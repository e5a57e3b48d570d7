//! `cumulus bench`: a tiny run's tables, and the convergence of its render
//! reference.

mod clipmap;
mod gpu_check;
mod reference_convergence;
mod run;
